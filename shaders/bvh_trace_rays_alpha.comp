#version 460
// bvh_trace_rays_alpha: bvh_trace_rays with OSR_BVH_ALPHA_TEST on and a test cutout function
// driven by a per-triangle mask buffer (kAlpha* in shared/bvh_trace.h), so the tests can check
// that alpha-masked hits are skipped by both queries.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_trace.h"
#define OSR_BVH_BINDING kBindingBvh
#define OSR_BVH_ALPHA_TEST

layout(std430, binding = kBindingAlphaMask) readonly buffer AlphaMask { uint gAlphaMask[]; };

bool osrAlphaCutout(uint triangle, vec2 barycentrics, vec3 rayOrigin, vec3 rayInvDir) {
  uint mask = gAlphaMask[triangle];
  float w0 = 1.0 - barycentrics.x - barycentrics.y;
  return mask == kAlphaCutAll || (mask == kAlphaCutNearV0 && w0 > 0.5);
}

#include "lib/bvh_trace_rays_main.glsl"
