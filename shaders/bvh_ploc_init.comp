#version 460
// bvh_ploc_init: leaf i of the sorted order (the build node bvh_lbvh would make) and cluster i,
// which holds it; invocation 0 also sets the clusters' quantization frame: a cube twice the
// largest extent of the centroid bounds, centred on them, in kPlocQuantizeMax steps. One invocation per
// triangle. Inputs: sorted triangle indices (values), prims (through texels), info. Outputs:
// leaves (all fields but parent, which the merge that takes the leaf writes), the first
// clusters (bound as the next clusters), state.frame.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
layout(std430, binding = kPlocBindingValues) readonly buffer Values { uint gValues[]; };
layout(std430, binding = kPlocBindingInfo) readonly buffer Info { BvhBuildInfo gInfo; };
#define OSR_BUILD_TEXEL_BINDING kPlocBindingTexels
#include "lib/bvh_build_texels.glsl"

float decode(uint o) { return uintBitsToFloat(bvhBitsFromOrdered(o)); }

void main() {
  uint i = bvhBuildItem();
  if (i >= gPush.triangleCount) return;
  vec3 lo = vec3(decode(gInfo.centroidMin.x), decode(gInfo.centroidMin.y), decode(gInfo.centroidMin.z));
  vec3 hi = vec3(decode(gInfo.centroidMax.x), decode(gInfo.centroidMax.y), decode(gInfo.centroidMax.z));
  vec3 d = hi - lo;
  float extent = max(max(d.x, d.y), d.z);
  extent = extent > 0.0 && extent < 1.0e38 ? extent : 1.0;
  vec4 frame = vec4(0.5 * (lo + hi) - vec3(extent), float(kPlocQuantizeMax) / (2.0 * extent));
  if (i == 0u) gState.frame = frame;
  uint tri = gValues[i];
  BvhBuildNode leaf = sortedLeafNode(readPrim(tri), tri);
  initLeaf(i, leaf);
  plocStoreCluster(i, plocQuantize(leaf.lo, leaf.hi, frame, interiorCount() + i));
}
