#version 460
// bvh_ploc_nearest: each cluster's nearest neighbour (plocNearestNeighbour, lib/bvh_ploc_steps.glsl).
// Input: clusters (texels). Output: nearest.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"
layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
#define OSR_SUBTREE_NODES_BINDING kPlocBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"
#include "lib/bvh_ploc_steps.glsl"
PlocCluster plocSearchCluster(uint i) { return plocCluster(i); }
void main() {
  uint count = plocClusterCount();
  uint i = bvhBuildItem();
  if (i >= count) return;
  gNearest[i] = plocNearestNeighbour(i, count);
}
