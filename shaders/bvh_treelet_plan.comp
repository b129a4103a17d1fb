#version 460
// bvh_treelet_plan: exclusive scan of the per-height counts into list offsets and cursors, and
// the indirect dispatch arguments of each height's bvh_treelet dispatch. One invocation
// (kTreeletMaxLevels entries), so no cross-workgroup coordination.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = 1) in;
#include "lib/bvh_build_nodes.glsl"
#include "lib/bvh_treelet_schedule.glsl"

void main() {
  uint offset = 0u;
  for (uint h = 0u; h < kTreeletMaxLevels; ++h) {
    uint count = gLevels[h].count;
    gLevels[h].offset = offset;
    gLevels[h].cursor = offset;
    // Rows of at most kMaxGroupsX groups (bvhBuildItem), as few groups as possible past count.
    uint groups = (count + kWorkgroupSize - 1u) / kWorkgroupSize;
    uint rows = max(1u, (groups + kMaxGroupsX - 1u) / kMaxGroupsX);
    gDispatch[h].x = (groups + rows - 1u) / rows;
    gDispatch[h].y = rows;
    gDispatch[h].z = 1u;
    offset += count;
  }
}
