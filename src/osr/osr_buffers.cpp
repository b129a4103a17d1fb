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

std::vector<vk::ComputePipeline::Descriptor> osrDescriptors(
    const OsrBuffers& b, const render::Film& film, const bvh::Bvh& bvh,
    const scene::GpuScene& scene) {
  static_assert(o::kOsrSceneBinding == o::kOsrBvhBinding + gpu::bvh::kBvhBindingCount);
  static_assert(o::kOsrSceneTexelBinding == o::kOsrSceneBinding + gpu::scene::kSceneBindingCount);
  static_assert(o::kOsrBindingCount ==
                o::kOsrSceneTexelBinding + gpu::scene::kSceneTexelBindingCount);
  using D = vk::ComputePipeline::Descriptor;
  // Every slot is assigned below; the placeholder only gives the vector its size.
  std::vector<D> d(o::kOsrBindingCount, D(vk::BufferRange(b.frame)));
  d[o::kOsrBindingFrame] = D(vk::BufferRange(b.frame));
  d[o::kOsrBindingGBuffer] = D(vk::BufferRange(b.gbuffer));
  d[o::kOsrBindingAccum] = D(vk::BufferRange(b.accum));
  d[o::kOsrBindingMapRecords] = D(vk::BufferRange(b.mapRecords));
  d[o::kOsrBindingMapClean] = D(vk::BufferRange(b.mapClean));
  d[o::kOsrBindingMapOneShot] = D(vk::BufferRange(b.oneShot));
  d[o::kOsrBindingMapStats] = D(vk::BufferRange(b.mapStats));
  d[o::kOsrBindingNetIn] = D(vk::BufferRange(b.netIn));
  d[o::kOsrBindingNetOut] = D(vk::BufferRange(b.netOut));
  d[o::kOsrBindingFilm] = D(vk::BufferRange(film.buffer()));
  auto bvhD = bvh.descriptors();
  std::copy(bvhD.begin(), bvhD.end(), d.begin() + o::kOsrBvhBinding);
  auto sceneB = scene.bindings();
  for (size_t i = 0; i < sceneB.size(); ++i) d[o::kOsrSceneBinding + i] = D(sceneB[i]);
  auto texels = scene.texelViews();
  for (size_t i = 0; i < texels.size(); ++i) d[o::kOsrSceneTexelBinding + i] = D(texels[i]);
  return d;
}

}  // namespace osr::oneshot
