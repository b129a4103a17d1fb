// The world-space map cache's bindings and keys (shared/osr.h MapCacheEntry, docs/osr.md "The
// map cache"): a grid point's cell key and set, and the buffers of the cache's passes.
// Requires lib/osr_common.glsl (pcgHash, gFrame).
#ifndef OSR_LIB_OSR_MAP_CACHE_GLSL
#define OSR_LIB_OSR_MAP_CACHE_GLSL

layout(std430, binding = kOsrBindingCacheEntries) buffer OsrCacheEntries {
  MapCacheEntry gCacheEntries[];
};
layout(std430, binding = kOsrBindingCacheClean) buffer OsrCacheClean { float gCacheClean[]; };
layout(std430, binding = kOsrBindingCacheClaims) buffer OsrCacheClaims { uint gCacheClaims[]; };
layout(std430, binding = kOsrBindingCacheRefs) buffer OsrCacheRefs { MapCacheRef gCacheRefs[]; };

// The cell of world point x for a grid of world spacing `spacing` (shared/osr.h
// mapCacheCellLevel), with the dominant axis of the normal n (6 buckets), so the two sides of
// a thin wall never share a map. Never 0 (the empty slot's key).
uint mapCacheKey(vec3 x, vec3 n, float spacing, float cellScale) {
  int level = mapCacheCellLevel(spacing, cellScale);
  ivec3 c = ivec3(floor(x * exp2(float(-level))));
  vec3 a = abs(n);
  uint axis = a.x >= a.y && a.x >= a.z ? 0u : (a.y >= a.z ? 1u : 2u);
  uint bucket = axis * 2u + (n[axis] < 0.0 ? 1u : 0u);
  uint h = pcgHash(uint(level + 1024) * 6u + bucket);
  h = pcgHash(h ^ uint(c.x));
  h = pcgHash(h ^ uint(c.y));
  h = pcgHash(h ^ uint(c.z));
  return max(h, 1u);
}

uint mapCacheSet(uint key, uint sets) { return pcgHash(key ^ 0x5bd1e995u) % sets; }

// World spacing of grid radius r at a G-buffer surface: r pixel footprints there.
float gridSpacing(GBufferPixel g, uint radius) { return pixelFootprint(g) * float(radius); }

#endif
