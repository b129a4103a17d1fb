#version 460
// osr_cache_store: the traced maps the cache keeps (osr_cache_claim), after the denoiser. An
// inserted map is copied into its slot with its point, normal and grid spacing; a refined one
// is averaged into its slot's map, weighted by the map passes already in it, and the pass uses
// the average too (its MapPoint becomes the slot's: the average lives in the slot's frame).
// One invocation per (map, texel) of the chunk; texel 0 writes the entry and frees the claim.
// In: clean maps, MapPoint, MapCacheRef. Out: cache entries and clean maps, claims; clean map
// and MapPoint of refined maps.
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
  MapCacheRef ref = gCacheRefs[map];
  bool refine = ref.action == kMapCacheRefine;
  if (!refine && ref.action != kMapCacheInsert) return;
  uint src = local * 3u * kMapTexels + texel;  // gMapClean's window starts at mapOffset
  uint dst = ref.slot * 3u * kMapTexels + texel;
  float n = float(ref.passes);
  for (uint c = 0u; c < 3u; ++c) {
    float fresh = gMapClean[src + c * kMapTexels];
    if (refine) {
      float mean = (gCacheClean[dst + c * kMapTexels] * n + fresh) / (n + 1.0);
      gCacheClean[dst + c * kMapTexels] = mean;
      gMapClean[src + c * kMapTexels] = mean;
    } else {
      gCacheClean[dst + c * kMapTexels] = fresh;
    }
  }
  if (texel != 0u) return;
  gCacheClaims[ref.slot] = kMapCacheNone;
  MapPoint point = gMapPoints[map];
  if (refine) {
    gCacheEntries[ref.slot].state = uvec4(ref.key, gPush.clock, ref.passes + 1u, gPush.generation);
    point.position.xyz = gCacheEntries[ref.slot].position.xyz;
    point.normal.xyz = gCacheEntries[ref.slot].normal.xyz;
    point.pixel.z = 1u;
    gMapPoints[map] = point;
    return;
  }
  MapCacheEntry e;
  e.position = vec4(point.position.xyz, point.normal.w * float(gPush.grid.radius));
  e.normal = vec4(point.normal.xyz, 0.0);
  e.state = uvec4(ref.key, gPush.clock, 1u, gPush.generation);
  gCacheEntries[ref.slot] = e;
}
