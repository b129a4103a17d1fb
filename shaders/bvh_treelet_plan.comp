#version 460
// bvh_treelet_plan: exclusive scan of the per-bank, per-height counts into list offsets and
// bank cursors, the count of each height, and the indirect dispatch arguments of each height's
// bvh_treelet dispatch. One invocation (kTreeletMaxLevels x kTreeletBanks entries), so no
// cross-workgroup coordination.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = 1) in;
#include "lib/bvh_build_nodes.glsl"
#include "lib/bvh_treelet_schedule.glsl"

void main() {
  uint offset = 0u;
  for (uint h = 0u; h < kTreeletMaxLevels; ++h) {
    uint begin = offset;
    for (uint b = 0u; b < kTreeletBanks; ++b) {
      uint e = b * kTreeletMaxLevels + h;
      gBanks[e].y = offset;  // the bank's cursor: its part of the height's list
      offset += gBanks[e].x;
    }
    uint count = offset - begin;
    gLevels[h].count = count;
    gLevels[h].offset = begin;
    // Rows of at most kMaxGroupsX groups (bvhBuildItem), as few groups as possible past count.
    uint groups = (count + kWorkgroupSize - 1u) / kWorkgroupSize;
    uint rows = max(1u, (groups + kMaxGroupsX - 1u) / kMaxGroupsX);
    gDispatch[h].x = (groups + rows - 1u) / rows;
    gDispatch[h].y = rows;
    gDispatch[h].z = 1u;
  }
}
