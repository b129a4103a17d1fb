// Body of bvh_trace_rays.comp and its alpha-tested test variant. Each subgroup traces a pool of
// gPush.raysPerLane rays per invocation, a lane taking the pool's next ray once its ray is done
// (osrBvhTracePool in lib/bvh_traverse.glsl); raysPerLane = 1 is one ray per invocation, the
// way the renderers' kernels trace. The includer defines OSR_BVH_BINDING and, for the
// variant, OSR_BVH_ALPHA_TEST.
#ifndef OSR_BVH_TRACE_RAYS_MAIN_GLSL
#define OSR_BVH_TRACE_RAYS_MAIN_GLSL
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "shared/bvh_trace.h"
#define OSR_BVH_RAY_POOL
#include "lib/bvh_traverse.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kBindingRays) readonly buffer Rays { TraceRay gRays[]; };
layout(std430, binding = kBindingHits) writeonly buffer Hits { TraceHit gHits[]; };
layout(push_constant) uniform PushBlock { Push gPush; };

// The subgroup's pool: rays [gPoolNext, gPoolEnd) not yet taken (the same on every lane), and
// the lane's ray in flight.
uint gPoolNext = 0u, gPoolEnd = 0u;
uint gLaneRay = 0xffffffffu;  // none

// Idle lanes write their last ray's hit and take the pool's next rays, in lane order.
bool osrBvhPoolTake(bool idle, bool found, Hit hit, out OsrBvhPoolRayDesc next) {
  if (idle && gLaneRay != 0xffffffffu) {
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
    gHits[gLaneRay] = out_;
    gLaneRay = 0xffffffffu;
  }
  uvec4 takers = subgroupBallot(idle);
  uint slot = gPoolNext + subgroupBallotExclusiveBitCount(takers);
  gPoolNext += subgroupBallotBitCount(takers);
  if (!idle || slot >= gPoolEnd) return false;
  TraceRay ray = gRays[slot];
  next = OsrBvhPoolRayDesc(ray.origin, ray.tMin, ray.dir, ray.tMax, gPush.mode == kModeAny);
  gLaneRay = slot;
  return true;
}

void main() {
  // The subgroup's pool: raysPerLane rays for each of its invocations, in invocation order.
  // Workgroups hold whole subgroups (kWorkgroupSize is a multiple of every subgroup size up to
  // 64), so the pools of all subgroups tile [0, rayCount).
  uint workgroup = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  uint firstInvocation = workgroup * kWorkgroupSize + gl_SubgroupID * gl_SubgroupSize;
  gPoolNext = firstInvocation * gPush.raysPerLane;
  gPoolEnd = min(gPoolNext + gl_SubgroupSize * gPush.raysPerLane, gPush.rayCount);
  if (gPoolNext >= gPush.rayCount) return;
  osrBvhTracePool();
}
#endif
