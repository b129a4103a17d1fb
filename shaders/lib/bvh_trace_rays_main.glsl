// Body of bvh_trace_rays.comp and its alpha-tested test variant: one invocation per ray.
// The includer defines OSR_BVH_BINDING and, for the variant, OSR_BVH_ALPHA_TEST.
#ifndef OSR_BVH_TRACE_RAYS_MAIN_GLSL
#define OSR_BVH_TRACE_RAYS_MAIN_GLSL
#include "shared/bvh_trace.h"
#include "lib/bvh_traverse.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kBindingRays) readonly buffer Rays { TraceRay gRays[]; };
layout(std430, binding = kBindingHits) writeonly buffer Hits { TraceHit gHits[]; };
layout(push_constant) uniform PushBlock { Push gPush; };

void main() {
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gPush.rowInvocations;
  if (i >= gPush.rayCount) return;
  TraceRay ray = gRays[i];
  TraceHit out_;
  if (gPush.mode == kModeAny) {
    bool occluded = bvhAnyHit(ray.origin, ray.dir, ray.tMin, ray.tMax);
    out_.t = 0.0;
    out_.triangle = occluded ? 0u : kNoHit;
    out_.barycentrics = vec2(0.0);
  } else {
    Hit hit;
    bool found = bvhClosestHit(ray.origin, ray.dir, ray.tMin, ray.tMax, hit);
    out_.t = hit.t;
    out_.triangle = found ? hit.triangle : kNoHit;
    out_.barycentrics = hit.barycentrics;
  }
  gHits[i] = out_;
}
#endif
