#version 460
// bvh_ploc_merge: one invocation per mutual pair of this iteration (bvh_ploc_compact's list):
// their parent (plocMergePair, lib/bvh_ploc_steps.glsl). Inputs: pairs, build nodes and counts
// (texels; nodes of earlier iterations or of bvh_ploc_local). Outputs: interior nodes, parents,
// subtree node counts, state.root.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"
layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
#define OSR_BUILD_TEXEL_BINDING kPlocBindingTexels
#include "lib/bvh_build_texels.glsl"
#define OSR_SUBTREE_NODES_BINDING kPlocBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"
#include "lib/bvh_ploc_steps.glsl"
BvhBuildNode plocChildNode(uint u) { return readNode(u); }
uint plocChildSubtreeNodes(uint u) { return subtreeNodesOf(u); }
void main() {
  uint k = bvhBuildItem();
  if (k >= gState.pairs) return;
  uvec4 pair = gPairs[k];
  plocMergePair(pair.x, pair.y, pair.z, plocClusterCount() == 2u);
}
