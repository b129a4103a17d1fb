// The world-space map cache (docs/osr.md "The map cache"): clean hemisphere maps kept on the
// device across passes, camera moves and animation frames, keyed by a world cell and the
// normal's dominant axis (shared/osr.h MapCacheEntry, lib/osr_map_cache.glsl), in a
// set-associative table of fixed size whose sets replace their least recently used map.
// The passes that read and fill it are osr_cache_lookup, osr_cache_claim and osr_cache_store
// (osr_passes.h); OsrIntegrator records them around each chunk of maps.
#pragma once
#include <cstdint>

#include "shaders/shared/osr.h"
#include "vk/buffer.h"
#include "vk/context.h"

namespace osr::oneshot {

class MapCache {
 public:
  // Room for `maps` maps (rounded down to whole sets of kMapCacheWays, at least one set; 12 KiB
  // each on the device). Throws DeviceError where the clean maps do not fit one binding.
  MapCache(const vk::Context& ctx, uint32_t maps);

  uint32_t slots() const { return sets_ * gpu::osr::kMapCacheWays; }
  uint32_t sets() const { return sets_; }
  // Maps of other generations are stale: a scene change (material, light, geometry,
  // environment) makes every cached map stale; their slots are reused first.
  uint32_t generation() const { return generation_; }
  void invalidate() { ++generation_; }
  // The cache's time, one tick per map pass, for least-recently-used replacement.
  uint32_t tick() { return ++clock_; }
  uint32_t clock() const { return clock_; }
  // Every slot empty (submits and waits).
  void clear(const vk::Context& ctx);

  vk::Buffer entries;  // MapCacheEntry[slots]
  vk::Buffer clean;    // float[slots][3][32][32]
  vk::Buffer claims;   // uint[slots], kMapCacheNone between stores

 private:
  uint32_t sets_;
  uint32_t generation_ = 1;
  uint32_t clock_ = 0;
};

}  // namespace osr::oneshot
