// bvh_trace_rays.comp: traces a buffer of rays through the BVH and writes one hit record each.
// Used by the BVH tests (against a brute-force CPU loop) and by `osr-bench trace`.
#ifndef OSR_SHARED_BVH_TRACE_H
#define OSR_SHARED_BVH_TRACE_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(bvh_trace)
OSR_CONST(uint, kWorkgroupSize, 64u);
OSR_CONST(uint, kBindingRays, 0u);
OSR_CONST(uint, kBindingHits, 1u);
OSR_CONST(uint, kBindingBvh, 2u);  // kBvhBindingCount bindings from here
// Only in bvh_trace_rays_alpha.comp: one uint per triangle, see kAlpha* below.
OSR_CONST(uint, kBindingAlphaMask, 6u);

// constant_id of the kernel's choice: a subgroup pool of rays per lane (1), or one ray per
// invocation through bvhClosestHit / bvhAnyHit as the renderers trace (0). Two pipelines, so
// neither carries the other's code.
OSR_CONST(uint, kSpecRayPool, 0u);

OSR_CONST(uint, kModeClosest, 0u);
OSR_CONST(uint, kModeAny, 1u);
OSR_CONST(uint, kNoHit, 0xffffffffu);

// Test alpha masks (bvh_trace_rays_alpha.comp and its CPU twin): a triangle whose mask is
// kAlphaCutAll is a hole everywhere, kAlphaCutNearV0 a hole where the weight of v0 exceeds 0.5.
OSR_CONST(uint, kAlphaOpaque, 0u);
OSR_CONST(uint, kAlphaCutAll, 1u);
OSR_CONST(uint, kAlphaCutNearV0, 2u);

struct TraceRay {
  vec3 origin;
  float tMin;
  vec3 dir;
  float tMax;
};

// Closest mode: the hit, or triangle = kNoHit. Any mode: triangle = 0 when occluded, else kNoHit.
struct TraceHit {
  float t;
  uint triangle;
  vec2 barycentrics;
};

struct Push {
  uint rayCount;
  uint mode;
  uint raysPerLane;  // rays each subgroup's pool holds per invocation (1 with kSpecRayPool 0)
  uint _pad0;
};
OSR_NAMESPACE_END
#endif
