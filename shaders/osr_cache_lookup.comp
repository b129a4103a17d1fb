#version 460
// osr_cache_lookup: the world-space map cache's answer for each grid point of a chunk, before
// any map is traced (docs/osr.md "The map cache"). The point's cell key (lib/osr_map_cache.glsl)
// selects a set; a way with that key, of this scene generation, whose normal agrees within
// kMapCacheMinCos and whose grid was not more than kMapCacheSparse times coarser, is a hit.
// A hit whose map averages more map passes than this restart has made, and at least
// gPush.maturePasses, is reused (copied into the pass's clean maps and MapPoint, not traced);
// one that averages fewer is refined (traced, then averaged in by osr_cache_store); a
// too-coarse hit is replaced; a miss is inserted.
// One invocation per (map, texel) of the chunk, each copying its texel of a reused map; texel
// 0 writes the MapCacheRef and marks the slot used at gPush.clock.
// In: GBufferPixel, cache. Out: MapCacheRef, MapPoint and clean map of reused maps.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/osr_maps.glsl"
#include "lib/osr_map_cache.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { MapCachePush gPush; };

void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * kOsrWorkgroupSize;
  uint local = id / kMapTexels;
  if (local >= gPush.mapCount) return;
  uint texel = id % kMapTexels;
  uint map = gPush.mapOffset + local;
  uvec2 pixel = mapPixel(gPush.grid, map);
  GBufferPixel g = gGBuffer[pixel.y * gFrame.width + pixel.x - gPush.gbufferWindowOffset];
  MapCacheRef ref;
  ref.action = kMapCacheTrace;
  ref.slot = kMapCacheNone;
  ref.key = 0u;
  ref.passes = 0u;
  if (g.position.w > 0.5) {
    float spacing = gridSpacing(g, gPush.grid.radius);
    ref.key = mapCacheKey(g.position.xyz, g.normal.xyz, spacing, gPush.cellScale);
    ref.action = kMapCacheInsert;
    uint set = mapCacheSet(ref.key, gPush.sets);
    for (uint way = 0u; way < kMapCacheWays; ++way) {
      uint slot = set * kMapCacheWays + way;
      // Field by field: texel 0 of other maps may be marking this slot used (state.y).
      if (gCacheEntries[slot].state.x != ref.key || gCacheEntries[slot].state.w != gPush.generation)
        continue;
      if (dot(gCacheEntries[slot].normal.xyz, g.normal.xyz) < kMapCacheMinCos) continue;
      ref.slot = slot;
      if (gCacheEntries[slot].position.w > kMapCacheSparse * spacing) break;  // replaced
      ref.passes = gCacheEntries[slot].state.z;
      bool reuse = ref.passes > gPush.mapPass && ref.passes >= gPush.maturePasses;
      ref.action = reuse ? kMapCacheReuse : kMapCacheRefine;
      break;
    }
  }
  if (ref.action == kMapCacheReuse) {
    uint src = ref.slot * 3u * kMapTexels + texel;
    uint dst = local * 3u * kMapTexels + texel;  // gMapClean's window starts at mapOffset
    for (uint c = 0u; c < 3u; ++c) gMapClean[dst + c * kMapTexels] = gCacheClean[src + c * kMapTexels];
  }
  if (texel != 0u) return;
  gCacheRefs[map] = ref;
  if (ref.action == kMapCacheReuse || ref.action == kMapCacheRefine)
    gCacheEntries[ref.slot].state.y = gPush.clock;
  if (ref.action == kMapCacheReuse) {
    MapPoint point;
    point.position = vec4(gCacheEntries[ref.slot].position.xyz, 1.0);
    point.normal = vec4(gCacheEntries[ref.slot].normal.xyz, pixelFootprint(g));
    point.pixel = uvec4(pixel, 1u, 0u);
    gMapPoints[map] = point;
  }
}
