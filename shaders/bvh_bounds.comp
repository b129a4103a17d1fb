#version 460
// bvh_bounds: for each triangle, a copy of its world-space vertices (BvhLeafTriangle, scene
// index in v0.w) and the scene's centroid bounds: subgroup min/max, then one atomic per
// subgroup on order-preserving uints (bvhOrderedFromBits). Inputs: scene triangles and vertices
// (two chunks of one buffer, see shared/bvh_build.h). Outputs: prims, info.centroidMin/Max,
// which the caller has set to the empty box. Precondition: vertex indices in range.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "shared/bvh_build.h"
#include "shared/scene.h"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kBoundsBindingTriangles) readonly buffer Triangles { Triangle gTriangles[]; };
layout(std430, binding = kBoundsBindingVerticesLo) readonly buffer VerticesLo { Vertex gVerticesLo[]; };
layout(std430, binding = kBoundsBindingVerticesHi) readonly buffer VerticesHi { Vertex gVerticesHi[]; };
layout(std430, binding = kBoundsBindingPrims) writeonly buffer Prims { BvhLeafTriangle gPrims[]; };
layout(std430, binding = kBoundsBindingInfo) buffer Info { BvhBuildInfo gInfo; };
layout(push_constant) uniform PushBlock { BuildPush gPush; };

vec3 position(uint v) {
  uint lo = gPush.param;
  return v < lo ? gVerticesLo[v].position : gVerticesHi[v - lo].position;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  bool inRange = i < gPush.triangleCount;
  vec3 cmin = vec3(3.0e38), cmax = vec3(-3.0e38);
  if (inRange) {
    Triangle t = gTriangles[i];
    vec3 p0 = position(t.v0), p1 = position(t.v1), p2 = position(t.v2);
    gPrims[i].v0 = vec4(p0, uintBitsToFloat(i));
    gPrims[i].v1 = vec4(p1, 0.0);
    gPrims[i].v2 = vec4(p2, 0.0);
    vec3 c = 0.5 * (min(min(p0, p1), p2) + max(max(p0, p1), p2));
    cmin = c;
    cmax = c;
  }
  cmin = subgroupMin(cmin);
  cmax = subgroupMax(cmax);
  if (subgroupElect()) {
    for (int k = 0; k < 3; ++k) {
      atomicMin(gInfo.centroidMin[k], bvhOrderedFromBits(floatBitsToUint(cmin[k])));
      atomicMax(gInfo.centroidMax[k], bvhOrderedFromBits(floatBitsToUint(cmax[k])));
    }
  }
}
