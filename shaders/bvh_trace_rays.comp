#version 460
// bvh_trace_rays: closest-hit or any-hit query for each ray of a buffer (push mode).
// Inputs: rays (TraceRay), the BVH. Output: one TraceHit per ray. The reusable batch tracer of
// the BVH tests and of `osr-bench trace`.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_trace.h"
#define OSR_BVH_BINDING kBindingBvh
#include "lib/bvh_trace_rays_main.glsl"
