#include "osr/map_cache.h"

#include <algorithm>
#include <string>

#include "common/error.h"
#include "osr/osr_buffers.h"

namespace osr::oneshot {

namespace o = gpu::osr;

MapCache::MapCache(const vk::Context& ctx, uint32_t maps)
    : sets_(std::max(1u, maps / o::kMapCacheWays)) {
  const VkDeviceSize cleanBytes = VkDeviceSize(slots()) * kCleanMapBytes;
  if (cleanBytes > ctx.caps().maxStorageBufferRange)
    throw DeviceError("osr: a map cache of " + std::to_string(slots()) + " maps needs " +
                      std::to_string(cleanBytes >> 20) +
                      " MiB in one binding, over the device's maxStorageBufferRange of " +
                      std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB");
  entries = vk::Buffer(ctx, slots() * sizeof(o::MapCacheEntry), vk::MemoryUse::DeviceLocal,
                       "osr map cache entries");
  clean = vk::Buffer(ctx, cleanBytes, vk::MemoryUse::DeviceLocal, "osr map cache clean maps");
  claims = vk::Buffer(ctx, slots() * sizeof(uint32_t), vk::MemoryUse::DeviceLocal,
                      "osr map cache claims");
  clear(ctx);
}

void MapCache::clear(const vk::Context& ctx) {
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, entries.handle(), 0, VK_WHOLE_SIZE, 0u);
    vkCmdFillBuffer(cmd, clean.handle(), 0, VK_WHOLE_SIZE, 0u);
    vkCmdFillBuffer(cmd, claims.handle(), 0, VK_WHOLE_SIZE, o::kMapCacheNone);
  });
}

}  // namespace osr::oneshot
