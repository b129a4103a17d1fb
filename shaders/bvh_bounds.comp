#version 460
// bvh_bounds: for each triangle, a copy of its world-space vertices (BvhLeafTriangle, scene
// index in v0.w) and the scene's centroid bounds: subgroup min/max, then one atomic per
// subgroup and axis where that grows the box, on order-preserving uints (bvhOrderedFromBits).
// Inputs: scene triangles and vertices (lib/bvh_build_arrays.glsl, or texel views of them where
// kSceneTexels is set, shared/bvh_build.h). Outputs: prims,
// info.centroidMin/Max, which the caller has set to the empty box. Precondition: vertex indices
// in range.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kBoundsBindingInfo) buffer Info { BvhBuildInfo gInfo; };
layout(binding = kBoundsBindingTriangleTexels) uniform usamplerBuffer gTriangleTexels;
layout(binding = kBoundsBindingVertexTexels) uniform usamplerBuffer gVertexTexels;

layout(constant_id = kBoundsSpecSceneTexels) const bool kSceneTexels = false;
// Triangle i's vertex positions, from the scene's texel views or its storage arrays.
void loadCorners(uint i, out vec3 p0, out vec3 p1, out vec3 p2) {
  if (kSceneTexels) {
    uvec4 t = texelFetch(gTriangleTexels, int(i));
    p0 = uintBitsToFloat(texelFetch(gVertexTexels, int(2u * t.x)).xyz);
    p1 = uintBitsToFloat(texelFetch(gVertexTexels, int(2u * t.y)).xyz);
    p2 = uintBitsToFloat(texelFetch(gVertexTexels, int(2u * t.z)).xyz);
    return;
  }
  Triangle t = loadTriangle(i);
  p0 = loadPosition(t.v0);
  p1 = loadPosition(t.v1);
  p2 = loadPosition(t.v2);
}


void main() {
  uint i = bvhBuildItem();
  bool inRange = i < gPush.triangleCount;
  vec3 cmin = vec3(3.0e38), cmax = vec3(-3.0e38);
  if (inRange) {
    vec3 p0, p1, p2;
    loadCorners(i, p0, p1, p2);
    storePrim(i, BvhLeafTriangle(vec4(p0, uintBitsToFloat(i)), vec4(p1, 0.0), vec4(p2, 0.0)));
    vec3 c = 0.5 * (min(min(p0, p1), p2) + max(max(p0, p1), p2));
    cmin = c;
    cmax = c;
  }
  cmin = subgroupMin(cmin);
  cmax = subgroupMax(cmax);
  // An atomic only where the box grows past what was read: the bounds only grow, so a skipped
  // atomic could not have changed them. Most subgroups then only read the shared cache line
  // instead of taking it from the other thread for a compare-and-swap loop.
  if (subgroupElect()) {
    for (int k = 0; k < 3; ++k) {
      uint lo = bvhOrderedFromBits(floatBitsToUint(cmin[k])), hi = bvhOrderedFromBits(floatBitsToUint(cmax[k]));
      if (lo < gInfo.centroidMin[k]) atomicMin(gInfo.centroidMin[k], lo);
      if (hi > gInfo.centroidMax[k]) atomicMax(gInfo.centroidMax[k], hi);
    }
  }
}
