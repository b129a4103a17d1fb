#include "osr/osr_buffers.h"

#include <algorithm>

namespace osr::oneshot {

namespace o = gpu::osr;

namespace {
constexpr VkDeviceSize kMapFloats = gpu::hemi::kMapTexels;
}

OsrBuffers::OsrBuffers(const vk::Context& ctx, uint32_t width, uint32_t height, uint32_t maxMaps_,
                       uint32_t chunkMaps_)
    : maxMaps(std::max(1u, maxMaps_)), chunkMaps(std::max(1u, std::min(chunkMaps_, maxMaps_))) {
  const VkDeviceSize pixels = VkDeviceSize(width) * height;
  auto make = [&](VkDeviceSize bytes, const char* name) {
    if (bytes > ctx.caps().maxStorageBufferRange)
      throw DeviceError(std::string("osr: ") + name + " needs " + std::to_string(bytes >> 20) +
                        " MiB, over the device's maxStorageBufferRange of " +
                        std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB");
    return vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, std::string("osr ") + name);
  };
  frame = make(sizeof(gpu::camera::CameraFrame), "camera frame");
  gbuffer = make(pixels * sizeof(o::GBufferPixel), "g-buffer");
  accum = make(pixels * sizeof(o::AccumPixel), "accumulation");
  mapRecords = make(maxMaps * sizeof(o::MapRecord), "map records");
  mapClean = make(maxMaps * 3 * kMapFloats * sizeof(float), "clean maps");
  oneShot = make(chunkMaps * o::kMapChannels * kMapFloats * sizeof(float), "one-shot maps");
  mapStats = make(chunkMaps * sizeof(o::MapStats), "map statistics");
  netIn = make(chunkMaps * o::kMapChannels * kMapFloats * sizeof(float), "network input");
  netOut = make(chunkMaps * 3 * kMapFloats * sizeof(float), "network output");
}

std::vector<VkDescriptorType> osrDescriptorTypes() {
  std::vector<VkDescriptorType> types(o::kOsrBindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  auto bvhTypes = bvh::Bvh::descriptorTypes();
  std::copy(bvhTypes.begin(), bvhTypes.end(), types.begin() + o::kOsrBvhBinding);
  std::fill(types.begin() + o::kOsrSceneTexelBinding,
            types.begin() + o::kOsrSceneTexelBinding + gpu::scene::kSceneTexelBindingCount,
            VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER);
  return types;
}

void OsrBindings::fill(vk::Binder& b) const {
  b.set(o::kOsrBindingFrame, buffers->frame)
      .set(o::kOsrBindingGBuffer, buffers->gbuffer)
      .set(o::kOsrBindingAccum, buffers->accum)
      .set(o::kOsrBindingMapRecords, buffers->mapRecords)
      .set(o::kOsrBindingMapClean, buffers->mapClean)
      .set(o::kOsrBindingMapOneShot, buffers->oneShot)
      .set(o::kOsrBindingMapStats, buffers->mapStats)
      .set(o::kOsrBindingNetIn, buffers->netIn)
      .set(o::kOsrBindingNetOut, buffers->netOut)
      .set(o::kOsrBindingFilm, film->buffer());
  bvh->bind(b, o::kOsrBvhBinding);
  scene->bind(b, o::kOsrSceneBinding);
  scene->bindTexels(b, o::kOsrSceneTexelBinding);
}

}  // namespace osr::oneshot
