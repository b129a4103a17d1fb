// The world-space map cache (docs/osr.md "The map cache"): clean hemisphere maps kept on the
// device across passes, camera moves and animation frames, keyed by a world cell and the
// normal's dominant axis (shared/osr.h MapCacheEntry, lib/osr_map_cache.glsl), in a
// set-associative table of fixed size whose sets replace their least recently used map.
// The passes that read and fill it are osr_cache_lookup, osr_cache_claim and osr_cache_store
// (osr_passes.h); OsrIntegrator records them around each chunk of maps.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "shaders/shared/osr.h"
#include "vk/buffer.h"
#include "vk/context.h"

namespace osr::oneshot {

// A box whose surroundings changed (an object that moved: its bounds before, or after), and
// how far from it cached maps are made stale.
struct MapCacheRegion {
  glm::vec3 lo{0.0f}, hi{0.0f};
  float reach = 0.0f;  // world units from the box
};

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
  // Maps of the current generation (downloads the entries).
  uint32_t liveMaps() const;
  // Makes stale each live map that may serve a point within `reach` of a region's box: its
  // position within reach plus its cell's diagonal (a map serves the grid points of its cell,
  // shared/osr.h mapCacheCellLevel; cellScale: OsrSettings::mapCacheCellScale). A walk on the
  // host: the entries are 48 bytes a map (192 KiB for 4096 maps), downloaded and uploaded
  // once per frame that moves something, 0.08 ms on lavapipe (test osr/test_map_cache), far
  // less than one map pass; it keeps the rule plain C++, where a compute pass would need a
  // buffer of regions and a binding of its own. Submits and waits: no submission may use the
  // cache meanwhile. Returns the maps made stale and the live maps kept.
  struct Invalidated {
    uint32_t stale = 0, kept = 0;
  };
  Invalidated invalidateNear(const std::vector<MapCacheRegion>& regions, float cellScale);

  vk::Buffer entries;  // MapCacheEntry[slots]
  vk::Buffer clean;    // float[slots][3][32][32]
  vk::Buffer claims;   // uint[slots], kMapCacheNone between stores

 private:
  uint32_t sets_;
  uint32_t generation_ = 1;
  uint32_t clock_ = 0;
};

}  // namespace osr::oneshot
