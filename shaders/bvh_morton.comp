#version 460
// bvh_morton: key = 30-bit Morton code of the triangle's box centre within the scene centroid
// bounds (bvhMorton, shared with the C++ twin), value = triangle index. Inputs: prims (from
// bvh_bounds, through texels: on lavapipe a gather, where a storage load is a loop over the
// lanes), info.centroidMin/Max. Outputs: keys, values.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kMortonBindingInfo) readonly buffer Info { BvhBuildInfo gInfo; };
layout(std430, binding = kMortonBindingKeys) writeonly buffer Keys { uint gKeys[]; };
layout(std430, binding = kMortonBindingValues) writeonly buffer Values { uint gValues[]; };
#define OSR_BUILD_TEXEL_BINDING kMortonBindingTexels
#include "lib/bvh_build_texels.glsl"

float decode(uint o) { return uintBitsToFloat(bvhBitsFromOrdered(o)); }

void main() {
  uint i = bvhBuildItem();
  if (i >= gPush.triangleCount) return;
  vec3 lo = vec3(decode(gInfo.centroidMin.x), decode(gInfo.centroidMin.y), decode(gInfo.centroidMin.z));
  vec3 hi = vec3(decode(gInfo.centroidMax.x), decode(gInfo.centroidMax.y), decode(gInfo.centroidMax.z));
  vec3 extent = hi - lo;
  // A flat axis maps every centroid to 0 (no division by zero).
  vec3 scale = vec3(extent.x > 0.0 ? 1.0 / extent.x : 0.0, extent.y > 0.0 ? 1.0 / extent.y : 0.0,
                    extent.z > 0.0 ? 1.0 / extent.z : 0.0);
  BvhLeafTriangle p = readPrim(i);
  vec3 c = 0.5 * (min(min(p.v0.xyz, p.v1.xyz), p.v2.xyz) + max(max(p.v0.xyz, p.v1.xyz), p.v2.xyz));
  precise vec3 u = (c - lo) * scale;
  gKeys[i] = bvhMorton(u.x, u.y, u.z);
  gValues[i] = i;
}
