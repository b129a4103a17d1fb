#version 460
// bvh_subtree_count: how many traversal nodes each subtree holds, bottom-up: 0 for a leaf or a
// collapsed subtree, else 1 + its children's. One invocation per leaf climbs towards the root;
// at each parent the first to arrive (atomic counter) stops and the second sums, as in
// bvh_refit. bvh_emit_nodes places child b after child a's subtree with these counts. Links are
// read through texels (the treelet passes wrote them in earlier dispatches), sibling counts from
// the coherent array this dispatch writes.
// Inputs: final build topology and collapse flags; counters zeroed. Output: subtreeNodes.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_build_nodes.glsl"
#define OSR_BUILD_TEXEL_BINDING kSubtreeCountBindingTexels
#include "lib/bvh_build_texels.glsl"
layout(std430, binding = kSubtreeCountBindingNodes) coherent buffer SubtreeNodes { uint gSubtreeNodes[]; };

void main() {
  uint i = bvhBuildItem();
  if (i >= gPush.triangleCount) return;
  uint u = interiorCount() + i;
  uint count = 0u;  // traversal nodes in u's subtree
  uint p = readLeafTriangleAndParent(i).y;
  while (p != kInvalidNode) {
    climbFence();
    if (atomicAdd(gCounters[p], 1u) == 0u) break;
    climbFence();
    BuildLinks links = readLinks(p);
    uint sibling = links.left == u ? links.right : links.left;
    uint siblingCount = sibling < interiorCount() ? gSubtreeNodes[sibling] : 0u;
    count = subtreeNodesFrom(links.flags, count + siblingCount);
    gSubtreeNodes[p] = count;
    u = p;
    p = links.parent;
  }
}
