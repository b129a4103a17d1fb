#version 460
// bvh_ploc_init: leaf i of the sorted order (the build node bvh_lbvh would make) and cluster i,
// which holds it. One invocation per triangle. Inputs: sorted triangle indices (values), prims
// (through texels). Outputs: leaves (all fields but parent, which the merge that takes the leaf
// writes), the first clusters (bound as the next clusters).
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
layout(std430, binding = kPlocBindingValues) readonly buffer Values { uint gValues[]; };
#define OSR_BUILD_TEXEL_BINDING kPlocBindingTexels
#include "lib/bvh_build_texels.glsl"

void main() {
  uint i = bvhBuildItem();
  if (i >= gPush.triangleCount) return;
  uint tri = gValues[i];
  BvhBuildNode leaf = sortedLeafNode(readPrim(tri), tri);
  initLeaf(i, leaf);
  plocStoreCluster(i, PlocCluster(leaf.lo, leaf.hi, interiorCount() + i, i));
}
