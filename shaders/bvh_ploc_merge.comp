#version 460
// bvh_ploc_merge: one invocation per mutual pair of this iteration (bvh_ploc_compact's list):
// their parent, an interior node with everything bvh_refit would give it (refitNode from the
// children's build nodes), both children's parent and its subtree's traversal nodes. The root
// (this iteration had two clusters) takes index 0 and first moves the node there to the root's
// own index (a node that bvh_ploc_local made, too). Inputs: pairs, build nodes and counts
// (texels; nodes of earlier iterations or of bvh_ploc_local). Outputs: interior nodes, parents,
// subtree node counts.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
#define OSR_BUILD_TEXEL_BINDING kPlocBindingTexels
#include "lib/bvh_build_texels.glsl"
#define OSR_SUBTREE_NODES_BINDING kPlocBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"

// Points whatever referred to interior node 0 at `to` instead: its children's parent, its
// parent's child (unless its parent is still to be made: the root); and moves it.
void moveNodeZero(uint to) {
  BvhBuildNode w = loadInterior(0u);
  storeInterior(to, w);
  gSubtreeNodes[to] = gSubtreeNodes[0];
  setParent(w.left, to);
  setParent(w.right, to);
  if (w.parent != kInvalidNode) {
    BvhBuildNode q = loadInterior(w.parent);
    setChildren(w.parent, q.left == 0u ? to : q.left, q.right == 0u ? to : q.right);
  }
}

void main() {
  uint k = bvhBuildItem();
  if (k >= gState.pairs) return;
  uvec4 pair = gPairs[k];
  uint left = pair.x, right = pair.y, p = pair.z;
  bool isRoot = plocClusterCount() == 2u;
  if (isRoot && p != 0u) {
    moveNodeZero(p);
    left = left == 0u ? p : left;
    right = right == 0u ? p : right;
    p = 0u;
  }
  BvhBuildNode node;
  node.left = left;
  node.right = right;
  node.parent = kInvalidNode;  // until its own parent is made
  node = refitNode(node, readNode(pair.x), readNode(pair.y), isRoot);
  // Before the root's stores below overwrite index 0, which pair.x or pair.y may be.
  uint below = subtreeNodesOf(pair.x) + subtreeNodesOf(pair.y);
  storeInterior(p, node);
  setParent(left, p);
  setParent(right, p);
  gSubtreeNodes[p] = subtreeNodesFrom(node.flags, below);
}
