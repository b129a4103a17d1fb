#include "osr/map_cache.h"

#include <algorithm>
#include <cmath>
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

namespace {
// Distance from p to the box [lo, hi] (0 inside).
float distanceToBox(glm::vec3 p, glm::vec3 lo, glm::vec3 hi) {
  return glm::length(glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f)));
}
}  // namespace

uint32_t MapCache::liveMaps() const {
  uint32_t live = 0;
  for (const o::MapCacheEntry& e : entries.downloadVector<o::MapCacheEntry>(slots()))
    live += e.state.x != 0 && e.state.w == generation_;
  return live;
}

MapCache::Invalidated MapCache::invalidateNear(const std::vector<MapCacheRegion>& regions,
                                               float cellScale) {
  Invalidated result;
  std::vector<o::MapCacheEntry> e = entries.downloadVector<o::MapCacheEntry>(slots());
  bool changed = false;
  for (o::MapCacheEntry& entry : e) {
    if (entry.state.x == 0 || entry.state.w != generation_) continue;  // empty or stale
    const float cell = std::ldexp(1.0f, o::mapCacheCellLevel(entry.position.w, cellScale));
    const glm::vec3 p(entry.position);
    const bool near = std::any_of(regions.begin(), regions.end(), [&](const MapCacheRegion& r) {
      return distanceToBox(p, r.lo, r.hi) <= r.reach + std::sqrt(3.0f) * cell;
    });
    if (!near) {
      ++result.kept;
      continue;
    }
    // Generation 0 is never current (generation_ starts at 1 and only grows): stale for good,
    // and osr_cache_claim reuses its slot first.
    entry.state.w = 0;
    ++result.stale;
    changed = true;
  }
  if (changed) entries.uploadVector(e);
  return result;
}

}  // namespace osr::oneshot
