#version 460
// bvh_ploc_merge: one invocation per mutual pair of this iteration (bvh_ploc_compact's list):
// their parent, an interior node with everything bvh_refit would give it (refitNode from the
// children's build nodes), both children's parent and its subtree's traversal nodes. The root
// (this iteration had two clusters) is made at its own index like any node, which goes to
// PlocState.root for bvh_ploc_root. Inputs: pairs, build nodes and counts (texels; nodes of
// earlier iterations or of bvh_ploc_local). Outputs: interior nodes, parents, subtree node
// counts, state.root.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
#define OSR_BUILD_TEXEL_BINDING kPlocBindingTexels
#include "lib/bvh_build_texels.glsl"
#define OSR_SUBTREE_NODES_BINDING kPlocBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"

void main() {
  uint k = bvhBuildItem();
  if (k >= gState.pairs) return;
  uvec4 pair = gPairs[k];
  uint left = pair.x, right = pair.y, p = pair.z;
  bool isRoot = plocClusterCount() == 2u;
  if (isRoot) gState.root = p;  // bvh_ploc_root moves it to 0
  BvhBuildNode node;
  node.left = left;
  node.right = right;
  node.parent = kInvalidNode;  // until its own parent is made
  node = refitNode(node, readNode(pair.x), readNode(pair.y), isRoot);
  uint below = subtreeNodesOf(pair.x) + subtreeNodesOf(pair.y);
  storeInterior(p, node);
  setParent(left, p);
  setParent(right, p);
  gSubtreeNodes[p] = subtreeNodesFrom(node.flags, below);
}
