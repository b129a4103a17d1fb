// Build-node access for the bottom-up passes (bvh_refit, bvh_treelet): the two node arrays
// as one index space (shared/bvh_build.h) and the refit of one interior node.
#ifndef OSR_BVH_BUILD_NODES_GLSL
#define OSR_BVH_BUILD_NODES_GLSL
#include "lib/bvh_build_arrays.glsl"

// coherent: see the node arrays in lib/bvh_build_arrays.glsl.
layout(std430, binding = kClimbBindingCounters) coherent buffer Counters { uint gCounters[]; };

// Release the node just written before the counter atomic, acquire the sibling's after it. On
// lavapipe a memory barrier inside divergent control flow stalls the invocations that reach it
// (measured: the climb stopped after one level), and there every atomic is sequentially
// consistent on coherent host memory, so the build specialises the fences away on CPU devices.
layout(constant_id = kClimbSpecFences) const bool kClimbFences = true;
void climbFence() {
  if (kClimbFences) memoryBarrierBuffer();
}

bool isLeafNode(uint u) { return u >= interiorCount(); }

float boxArea(vec3 lo, vec3 hi) {
  vec3 d = max(hi - lo, vec3(0.0));
  return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

uint heightOf(BvhBuildNode n) { return n.flags & kHeightMask; }
uint traversalHeightOf(BvhBuildNode n) { return (n.flags >> kTraversalHeightShift) & kHeightMask; }

// Interior node n from its children: bounds, triangle count, SAH cost, collapse decision
// (a subtree of at most kBvhMaxLeafTriangles becomes one leaf when that is not more costly;
// never the root, which traversal needs as a node) and heights.
BvhBuildNode refitNode(BvhBuildNode n, BvhBuildNode l, BvhBuildNode r, bool isRoot) {
  n.lo = min(l.lo, r.lo);
  n.hi = max(l.hi, r.hi);
  n.triangleCount = l.triangleCount + r.triangleCount;
  float area = boxArea(n.lo, n.hi);
  float interiorCost = kSahNodeCost * area + l.cost + r.cost;
  float leafCost = kSahTriangleCost * area * float(n.triangleCount);
  bool collapse = !isRoot && n.triangleCount <= kBvhMaxLeafTriangles && leafCost <= interiorCost;
  n.cost = collapse ? leafCost : interiorCost;
  uint height = 1u + max(heightOf(l), heightOf(r));
  uint traversalHeight = collapse ? 0u : 1u + max(traversalHeightOf(l), traversalHeightOf(r));
  n.flags = (collapse ? kFlagCollapsed : 0u) | (traversalHeight << kTraversalHeightShift) | height;
  return n;
}

#endif
