// Shared by the treelet scheduling passes: which interior nodes a round restructures, and the
// schedule buffer (shared/bvh_build.h). The includer declares gPush (BuildPush) first and
// includes lib/bvh_build_nodes.glsl. Every treelet pass reads nodes that earlier dispatches
// wrote (bvh_treelet: but for the root it refits) through texels.
#ifndef OSR_BVH_TREELET_SCHEDULE_GLSL
#define OSR_BVH_TREELET_SCHEDULE_GLSL
#define OSR_BUILD_TEXEL_BINDING kTreeletBindingTexels
#include "lib/bvh_build_texels.glsl"

layout(std430, binding = kTreeletBindingSchedule) buffer Schedule {
  LevelList gLevels[kTreeletMaxLevels];
  DispatchArgs gDispatch[kTreeletMaxLevels];
  uvec2 gBanks[kTreeletBanks * kTreeletMaxLevels];  // (count, cursor) per bank and height
};
layout(std430, binding = kTreeletBindingNodeList) buffer NodeList { uint gNodeList[]; };

// Height bucket of interior node i this round, or -1 when it is not restructured. A collapsed
// node becomes one leaf whatever its topology, so it is left alone.
int treeletLevel(uint i, uint minTriangles) {
  BuildLinks n = readLinks(i);
  if ((n.flags & kFlagCollapsed) != 0u || n.triangleCount < minTriangles) return -1;
  uint h = n.flags & kHeightMask;
  return h < kTreeletMaxLevels ? int(h) : -1;
}

// The counters of height h in this invocation's workgroup's bank (bvh_treelet_count and
// _scatter agree on it).
uint treeletBankEntry(int h) {
  return (bvhBuildItem() / kWorkgroupSize) % kTreeletBanks * kTreeletMaxLevels + uint(h);
}

#endif
