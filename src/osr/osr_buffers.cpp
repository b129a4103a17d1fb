#include "osr/osr_buffers.h"

#include <algorithm>

namespace osr::oneshot {

namespace o = gpu::osr;

namespace {
constexpr VkDeviceSize kMapFloats = gpu::hemi::kMapTexels;
}  // namespace

// Multiples of 256 bytes (the largest minStorageBufferOffsetAlignment): windows may start at
// any map.
static_assert(kCleanMapBytes % 256 == 0 && kOneShotMapBytes % 256 == 0);

OsrBuffers::OsrBuffers(const vk::Context& ctx, uint32_t width, uint32_t height, uint32_t maxMaps_,
                       uint32_t chunkMaps_)
    : maxMaps(std::max(1u, maxMaps_)), chunkMaps(std::max(1u, std::min(chunkMaps_, maxMaps_))) {
  const VkDeviceSize pixels = VkDeviceSize(width) * height;
  enum Binding { Whole, Windows };
  auto make = [&](VkDeviceSize bytes, const char* name, Binding binding) {
    const bool whole = binding == Whole;
    const uint64_t limit =
        whole ? ctx.caps().maxStorageBufferRange : ctx.caps().maxMemoryAllocationSize;
    if (bytes > limit)
      throw DeviceError(std::string("osr: ") + name + " needs " + std::to_string(bytes >> 20) +
                        " MiB, over the device's " +
                        (whole ? "maxStorageBufferRange" : "maxMemoryAllocationSize") + " of " +
                        std::to_string(limit >> 20) + " MiB");
    return vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, std::string("osr ") + name);
  };
  frame = make(sizeof(gpu::camera::CameraFrame), "camera frame", Whole);
  gbuffer = make(pixels * sizeof(o::GBufferPixel), "g-buffer", Windows);
  accum = make(pixels * sizeof(o::AccumPixel), "accumulation", Windows);
  mapPoints = make(maxMaps * sizeof(o::MapPoint), "map points", Whole);
  mapProjections = make(maxMaps * sizeof(o::MapProjection), "map projections", Whole);
  mapClean = make(maxMaps * kCleanMapBytes, "clean maps", Windows);
  oneShot = make(chunkMaps * kOneShotMapBytes, "one-shot maps", Whole);
  mapStats = make(chunkMaps * sizeof(o::MapStats), "map statistics", Whole);
  netIn = make(chunkMaps * o::kMapChannels * kMapFloats * sizeof(float), "network input", Whole);
  netOut = make(chunkMaps * 3 * kMapFloats * sizeof(float), "network output", Whole);
  mapCacheRefs = make(maxMaps * sizeof(o::MapCacheRef), "map cache refs", Whole);
  // Every user starts with each point traced (kMapCacheTrace): a cache pass, where one runs,
  // rewrites them; the map tracer, which runs none, would otherwise read whatever memory held.
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, mapCacheRefs.handle(), 0, VK_WHOLE_SIZE, o::kMapCacheTrace);
  });
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

void OsrBindings::fill(vk::Binder& b, const OsrWindow& w) const {
  auto pixelRange = [&](const vk::Buffer& buffer, VkDeviceSize stride) {
    return vk::BufferRange(buffer, w.pixelFirst * stride, w.pixelCount * stride);
  };
  b.set(o::kOsrBindingFrame, buffers->frame)
      .set(o::kOsrBindingGBuffer, pixelRange(buffers->gbuffer, sizeof(o::GBufferPixel)))
      .set(o::kOsrBindingAccum, pixelRange(buffers->accum, sizeof(o::AccumPixel)))
      .set(o::kOsrBindingMapPoints, buffers->mapPoints)
      .set(o::kOsrBindingMapProjections, buffers->mapProjections)
      .set(o::kOsrBindingMapClean, vk::BufferRange(buffers->mapClean, w.mapFirst * kCleanMapBytes,
                                                   w.mapCount * kCleanMapBytes))
      .set(o::kOsrBindingMapOneShot,
           vk::BufferRange(buffers->oneShot, w.oneShotFirst * kOneShotMapBytes,
                           buffers->oneShot.size() - w.oneShotFirst * kOneShotMapBytes))
      .set(o::kOsrBindingMapStats, buffers->mapStats)
      .set(o::kOsrBindingNetIn, buffers->netIn)
      .set(o::kOsrBindingNetOut, buffers->netOut)
      .set(o::kOsrBindingFilm, film->window(w.pixelFirst, w.pixelCount))
      .set(o::kOsrBindingCacheEntries, cache->entries)
      .set(o::kOsrBindingCacheClean, cache->clean)
      .set(o::kOsrBindingCacheClaims, cache->claims)
      .set(o::kOsrBindingCacheRefs, buffers->mapCacheRefs);
  bvh->bind(b, o::kOsrBvhBinding);
  scene->bind(b, o::kOsrSceneBinding);
  scene->bindTexels(b, o::kOsrSceneTexelBinding);
}

}  // namespace osr::oneshot
