// Shared by the treelet scheduling passes: which interior nodes a round restructures, and the
// schedule buffer (shared/bvh_build.h). The includer declares gPush (BuildPush) first and
// includes lib/bvh_build_nodes.glsl.
#ifndef OSR_BVH_TREELET_SCHEDULE_GLSL
#define OSR_BVH_TREELET_SCHEDULE_GLSL

layout(std430, binding = kTreeletBindingSchedule) buffer Schedule {
  TreeletLevel gLevels[kTreeletMaxLevels];
  DispatchArgs gDispatch[kTreeletMaxLevels];
};
layout(std430, binding = kTreeletBindingNodeList) buffer NodeList { uint gNodeList[]; };

// Height bucket of interior node i this round, or -1 when it is not restructured. A collapsed
// node becomes one leaf whatever its topology, so it is left alone.
int treeletLevel(uint i, uint minTriangles) {
  BvhBuildNode n = loadInterior(i);
  if ((n.flags & kFlagCollapsed) != 0u || n.triangleCount < minTriangles) return -1;
  uint h = n.flags & kHeightMask;
  return h < kTreeletMaxLevels ? int(h) : -1;
}

#endif
