#version 460
// bvh_treelet_scatter: appends each node this round restructures to its height's list, in its
// bank's part (order within a height does not matter: those subtrees are disjoint).
// param = minTriangles.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_build_nodes.glsl"
#include "lib/bvh_treelet_schedule.glsl"

void main() {
  uint i = bvhBuildItem();
  if (i >= interiorCount()) return;
  int h = treeletLevel(i, gPush.param);
  if (h >= 0) gNodeList[atomicAdd(gBanks[treeletBankEntry(h)].y, 1u)] = i;
}
