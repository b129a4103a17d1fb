// The refit of one interior node from its children, for the passes that build nodes bottom-up
// (bvh_refit, bvh_treelet, bvh_ploc_merge). The includer has included lib/bvh_build_arrays.glsl.
#ifndef OSR_BVH_BUILD_REFIT_GLSL
#define OSR_BVH_BUILD_REFIT_GLSL

bool isLeafNode(uint u) { return u >= interiorCount(); }

float boxArea(vec3 lo, vec3 hi) {
  vec3 d = max(hi - lo, vec3(0.0));
  precise float area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);  // as refitNode's
  return area;
}

uint heightOf(BvhBuildNode n) { return n.flags & kHeightMask; }
uint traversalHeightOf(BvhBuildNode n) { return (n.flags >> kTraversalHeightShift) & kHeightMask; }

// Interior node n from its children: bounds, triangle count, SAH cost, collapse decision
// (a subtree of at most kBvhMaxLeafTriangles becomes one leaf when that is not more costly;
// never the root, which traversal needs as a node) and heights.
// Traversal nodes in the subtree of a node with these flags whose children's subtrees hold
// `below` (bvh_subtree_count's count): none where it collapses into a leaf.
uint subtreeNodesFrom(uint flags, uint below) { return (flags & kFlagCollapsed) != 0u ? 0u : 1u + below; }

BvhBuildNode refitNode(BvhBuildNode n, BvhBuildNode l, BvhBuildNode r, bool isRoot) {
  n.lo = min(l.lo, r.lo);
  n.hi = max(l.hi, r.hi);
  n.triangleCount = l.triangleCount + r.triangleCount;
  // precise: the passes that refit (bvh_ploc_merge, bvh_ploc_tail, ...) give the same bits.
  precise float area = boxArea(n.lo, n.hi);
  precise float interiorCost = kSahNodeCost * area + l.cost + r.cost;
  precise float leafCost = kSahTriangleCost * area * float(n.triangleCount);
  bool collapse = !isRoot && n.triangleCount <= kBvhMaxLeafTriangles && leafCost <= interiorCost;
  n.cost = collapse ? leafCost : interiorCost;
  uint height = 1u + max(heightOf(l), heightOf(r));
  uint traversalHeight = collapse ? 0u : 1u + max(traversalHeightOf(l), traversalHeightOf(r));
  n.flags = (collapse ? kFlagCollapsed : 0u) | (traversalHeight << kTraversalHeightShift) | height;
  return n;
}

#endif
