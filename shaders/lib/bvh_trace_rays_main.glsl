// Body of bvh_trace_rays.comp and its alpha-tested test variant. Each subgroup traces a pool of
// gPush.raysPerLane rays per invocation, a lane taking the pool's next ray when its ray is done
// (osrBvhTracePool in lib/bvh_traverse.glsl); the pipeline without kRayPool traces one ray per
// invocation with bvhClosestHit / bvhAnyHit, the way the renderers' kernels trace. The includer
// defines OSR_BVH_BINDING and, for the variant, OSR_BVH_ALPHA_TEST.
#ifndef OSR_BVH_TRACE_RAYS_MAIN_GLSL
#define OSR_BVH_TRACE_RAYS_MAIN_GLSL
#extension GL_KHR_shader_subgroup_basic : require
#include "shared/bvh_trace.h"
#define OSR_BVH_RAY_POOL
#include "lib/bvh_traverse.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kBindingRays) readonly buffer Rays { TraceRay gRays[]; };
layout(std430, binding = kBindingHits) writeonly buffer Hits { TraceHit gHits[]; };
layout(push_constant) uniform PushBlock { Push gPush; };
layout(constant_id = kSpecRayPool) const bool kRayPool = true;

OsrBvhPoolRayDesc osrBvhPoolRay(uint i) {
  TraceRay ray = gRays[i];
  return OsrBvhPoolRayDesc(ray.origin, ray.tMin, ray.dir, ray.tMax);
}

void osrBvhPoolResult(uint i, bool found, Hit hit) {
  TraceHit out_;
  if (gPush.mode == kModeAny) {
    out_.t = 0.0;
    out_.triangle = found ? 0u : kNoHit;
    out_.barycentrics = vec2(0.0);
  } else {
    out_.t = hit.t;
    out_.triangle = found ? hit.triangle : kNoHit;
    out_.barycentrics = hit.barycentrics;
  }
  gHits[i] = out_;
}

void main() {
  uint workgroup = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (!kRayPool) {
    // One ray per invocation, the way the renderers' kernels trace.
    uint i = workgroup * kWorkgroupSize + gl_LocalInvocationIndex;
    if (i >= gPush.rayCount) return;
    TraceRay ray = gRays[i];
    Hit hit = Hit(ray.tMax, kNoHit, vec2(0.0));
    bool found;
    if (gPush.mode == kModeAny)
      found = bvhAnyHit(ray.origin, ray.dir, ray.tMin, ray.tMax);
    else
      found = bvhClosestHit(ray.origin, ray.dir, ray.tMin, ray.tMax, hit);
    osrBvhPoolResult(i, found, hit);
    return;
  }
  // The subgroup's pool: raysPerLane rays for each of its invocations, in invocation order.
  // Workgroups hold whole subgroups (kWorkgroupSize is a multiple of every subgroup size up to
  // 64), so the pools of all subgroups tile [0, rayCount).
  uint firstInvocation = workgroup * kWorkgroupSize + gl_SubgroupID * gl_SubgroupSize;
  uint first = firstInvocation * gPush.raysPerLane;
  uint end = min(first + gl_SubgroupSize * gPush.raysPerLane, gPush.rayCount);
  if (first >= gPush.rayCount) return;
  // Two calls so that each query's loop is compiled for its mode.
  if (gPush.mode == kModeAny)
    osrBvhTracePool(first, end, true);
  else
    osrBvhTracePool(first, end, false);
}
#endif
