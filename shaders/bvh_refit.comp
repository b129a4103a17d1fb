#version 460
// bvh_refit: bounds, triangle counts, SAH costs, collapse flags and heights of every interior
// node, bottom-up. One invocation per leaf climbs towards the root; at each parent the first
// invocation to arrive (atomic counter) stops and the second refits it, so every node is
// refitted once, after both children, and no invocation ever waits for another.
// Each climbing invocation keeps the node it comes from in registers and reads only the
// sibling: leaves and the links of every node (bvh_lbvh's, which this pass leaves as they are)
// through texels, interior siblings (refitted in this dispatch) from the coherent array.
// Inputs: lbvh topology, leaf fields; counters zeroed. Output: interior node fields.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_build_nodes.glsl"
#define OSR_BUILD_TEXEL_BINDING kRefitBindingTexels
#include "lib/bvh_build_texels.glsl"

// Only the fields refitNode reads.
BvhBuildNode sibling(uint u) {
  if (isLeafNode(u)) return readNode(u);
  return loadInteriorSums(u);
}

void main() {
  uint i = bvhBuildItem();
  if (i >= gPush.triangleCount) return;
  uint u = interiorCount() + i;
  BvhBuildNode node = readNode(u);
  uint p = node.parent;
  while (p != kInvalidNode) {
    climbFence();
    if (atomicAdd(gCounters[p], 1u) == 0u) break;
    climbFence();
    BuildLinks links = readLinks(p);
    BvhBuildNode pn;
    pn.left = links.left;
    pn.right = links.right;
    pn.parent = links.parent;
    bool fromLeft = links.left == u;
    BvhBuildNode other = sibling(fromLeft ? links.right : links.left);
    pn = fromLeft ? refitNode(pn, node, other, p == 0u) : refitNode(pn, other, node, p == 0u);
    storeInteriorSums(p, pn);  // the links are bvh_lbvh's
    node = pn;
    u = p;
    p = links.parent;
  }
}
