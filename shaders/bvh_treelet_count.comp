#version 460
// bvh_treelet_count: number of nodes per height that this treelet round restructures
// (treeletLevel), per counter bank. Inputs: refitted build nodes, schedule zeroed. Output:
// gBanks[bank entry of h].x.
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
  if (h >= 0) atomicAdd(gBanks[treeletBankEntry(h)].x, 1u);
}
