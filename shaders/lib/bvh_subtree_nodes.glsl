// Traversal nodes per interior build node's subtree (bvh_subtree_count's array), for the passes
// that make nodes with their children at hand and so count them on the way (bvh_ploc_merge,
// bvh_treelet after PLOC): the builder then runs no bvh_subtree_count. The includer defines
// OSR_SUBTREE_NODES_BINDING (the storage binding; its R32UI view at the next slot) and has
// included lib/bvh_build_arrays.glsl.
#ifndef OSR_BVH_SUBTREE_NODES_GLSL
#define OSR_BVH_SUBTREE_NODES_GLSL

// coherent: bvh_ploc_tail reads counts that other invocations of its workgroup wrote.
layout(std430, binding = OSR_SUBTREE_NODES_BINDING) coherent buffer SubtreeNodes { uint gSubtreeNodes[]; };
layout(binding = OSR_SUBTREE_NODES_BINDING + 1) uniform usamplerBuffer gSubtreeNodeTexels;

// Build node u's count, written by an earlier dispatch (a leaf: 0; read on every lane, then
// chosen).
uint subtreeNodesOf(uint u) {
  uint ic = interiorCount();
  uint count = texelFetch(gSubtreeNodeTexels, int(min(u, ic - 1u))).x;
  return u < ic ? count : 0u;
}

#endif
