#version 460
// osr_cache_claim: which traced maps of a chunk the map cache keeps, the same whatever order
// the invocations run in (deterministic: the same seed gives the same image). Phase 0: each
// map to insert without a slot takes its set's victim (an empty or stale way first, else the
// least recently used one; never a way used in this map pass: if every way is, it is not
// stored), and every map to insert or refine claims its slot with atomicMin of its index.
// Phase 1: a map whose claim lost (another map of the chunk wants the slot) is only traced.
// osr_cache_store frees the claims it won. One invocation per map of the chunk.
// In/out: MapCacheRef, claims. In: cache entries.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/osr_maps.glsl"
#include "lib/osr_map_cache.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { MapCachePush gPush; };

void main() {
  uint local = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * kOsrWorkgroupSize;
  if (local >= gPush.mapCount) return;
  uint map = gPush.mapOffset + local;
  MapCacheRef ref = gCacheRefs[map];
  if (ref.action != kMapCacheInsert && ref.action != kMapCacheRefine) return;
  if (gPush.phase == 1u) {
    if (gCacheClaims[ref.slot] != map) {
      ref.action = kMapCacheTrace;
      gCacheRefs[map] = ref;
    }
    return;
  }
  if (ref.slot == kMapCacheNone) {
    uint set = mapCacheSet(ref.key, gPush.sets);
    uint best = kMapCacheNone;
    uint bestAge = 0u;
    for (uint way = 0u; way < kMapCacheWays; ++way) {
      uint slot = set * kMapCacheWays + way;
      uvec4 st = gCacheEntries[slot].state;
      bool live = st.x != 0u && st.w == gPush.generation;
      if (live && st.y == gPush.clock) continue;  // read or refined by this map pass
      uint age = live ? gPush.clock - st.y : 0xffffffffu;
      if (best == kMapCacheNone || age > bestAge) {
        best = slot;
        bestAge = age;
      }
    }
    ref.slot = best;
    if (best == kMapCacheNone) ref.action = kMapCacheTrace;
    gCacheRefs[map] = ref;
    if (best == kMapCacheNone) return;
  }
  atomicMin(gCacheClaims[ref.slot], map);
}
