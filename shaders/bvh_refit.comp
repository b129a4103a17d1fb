#version 460
// bvh_refit: bounds, triangle counts, SAH costs, collapse flags and heights of every interior
// node, bottom-up. One invocation per leaf climbs towards the root; at each parent the first
// invocation to arrive (atomic counter) stops and the second refits it, so every node is
// refitted once, after both children, and no invocation ever waits for another.
// Inputs: lbvh topology, leaf fields; counters zeroed. Output: interior node fields.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_build_nodes.glsl"

void main() {
  uint i = bvhBuildItem();
  if (i >= gPush.triangleCount) return;
  uint p = parentOf(interiorCount() + i);
  while (p != kInvalidNode) {
    climbFence();
    if (atomicAdd(gCounters[p], 1u) == 0u) break;
    climbFence();
    p = refitStored(p).parent;
  }
}
