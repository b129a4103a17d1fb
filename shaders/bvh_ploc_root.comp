#version 460
// bvh_ploc_root: one invocation, after the PLOC iterations. The last merge made the root at the
// index its leaves give it (PlocState.root); the root swaps places with the node at 0, where the
// emit passes and the host expect it, and every link to either follows. A pass of its own, not
// a branch in bvh_ploc_merge: on lavapipe a branch costs every lane of every subgroup, taken or
// not. Inputs/outputs: interior nodes, parents, subtree node counts; state.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"
layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
#define OSR_SUBTREE_NODES_BINDING kPlocBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"
void main() {
  uint r = gState.root;
  if (gl_GlobalInvocationID.x != 0u || r == 0u) return;
  BvhBuildNode root = loadInterior(r), moved = loadInterior(0u);
  uint rootNodes = gSubtreeNodes[r], movedNodes = gSubtreeNodes[0];
  // The moved node may be a child of the root.
  root.left = root.left == 0u ? r : root.left;
  root.right = root.right == 0u ? r : root.right;
  moved.parent = moved.parent == r ? 0u : moved.parent;
  storeInterior(0u, root);
  storeInterior(r, moved);
  gSubtreeNodes[0] = rootNodes;
  gSubtreeNodes[r] = movedNodes;
  setParent(root.left, 0u);
  setParent(root.right, 0u);
  setParent(moved.left, r);
  setParent(moved.right, r);
  BvhBuildNode above = loadInterior(moved.parent);  // not the root's: the root is not moved's child
  setChildren(moved.parent, above.left == 0u ? r : above.left, above.right == 0u ? r : above.right);
  gState.root = 0u;
}
