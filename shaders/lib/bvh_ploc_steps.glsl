// PLOC's nearest-neighbour search and merge, one text for the passes that run them one
// iteration per dispatch (bvh_ploc_nearest, bvh_ploc_merge), for bvh_ploc_tail, which runs
// many iterations in one workgroup and so reads what its own invocations wrote, and (the
// parent's making, plocStoreParent) for bvh_ploc_local, whose children are in registers. The includer
// defines where the clusters, the children's build nodes and their traversal-node counts come
// from (the prototypes below), after including lib/bvh_ploc.glsl and lib/bvh_subtree_nodes.glsl.
#ifndef OSR_BVH_PLOC_STEPS_GLSL
#define OSR_BVH_PLOC_STEPS_GLSL

PlocCluster plocSearchCluster(uint i);  // cluster i of this iteration
BvhBuildNode plocChildNode(uint u);     // build node u: a leaf, or an earlier merge's node
uint plocChildSubtreeNodes(uint u);     // traversal nodes below build node u (a leaf: 0)

// Cluster i's nearest neighbour among `count`: the cluster within kPlocRadius places whose union
// with it has the least surface area. Pairs are ordered by that area, then by their distance in
// Morton order, then by a hash of the pair, then by the lower index: one strict order of pairs
// that both clusters of a pair see, so the least pair is always mutual and every iteration
// merges. Ties matter where areas are equal (congruent triangles of a tessellation, which boxes
// quantized to 16 bits made common): broken by index alone, a run of equals merges one pair per
// iteration, and a large mesh's tree passed kBvhMaxDepth. A fixed trip count, places past the
// ends masked: every lane runs the same steps.
uint plocNearestNeighbour(uint i, uint count) {
  PlocCluster self = plocSearchCluster(i);
  float best = uintBitsToFloat(0x7f800000u);  // +inf: any neighbour beats it
  uint bestTie = 0u;
  uint nearest = i;
  for (uint k = 0u; k <= 2u * kPlocRadius; ++k) {
    uint j = i + k - kPlocRadius;  // wraps below 0: then past count
    bool valid = j < count && j != i;
    float a = plocUnionArea(self, plocSearchCluster(valid ? j : i));
    uint tie = plocTieKey(uint(abs(int(k) - int(kPlocRadius))), i, j);
    plocConsiderNeighbour(j, a, tie, valid, best, bestTie, nearest);
  }
  return nearest;
}

// Makes and stores the parent of build nodes left and right (whose nodes are l and r, with
// `childNodes` traversal nodes below them both) at interior index p, with everything bvh_refit
// would give it (refitNode), and its subtree's traversal-node count; returns the node. Its own
// parent is set when that is made; the children's parents are the caller's to set.
BvhBuildNode plocStoreParent(uint left, uint right, uint p, BvhBuildNode l, BvhBuildNode r, uint childNodes,
                             bool isRoot) {
  BvhBuildNode node;
  node.left = left;
  node.right = right;
  node.parent = kInvalidNode;  // until its own parent is made
  node = refitNode(node, l, r, isRoot);
  storeInterior(p, node);
  gSubtreeNodes[p] = subtreeNodesFrom(node.flags, childNodes);
  return node;
}

// The parent of a mutual pair of build nodes (left, right) at interior index p
// (plocStoreParent), and both children's parent. The root (the pair of the last two clusters)
// is made at its own index like any node, which goes to state.root for bvh_ploc_root.
void plocMergePair(uint left, uint right, uint p, bool isRoot) {
  plocStoreParent(left, right, p, plocChildNode(left), plocChildNode(right),
                  plocChildSubtreeNodes(left) + plocChildSubtreeNodes(right), isRoot);
  setParent(left, p);
  setParent(right, p);
  if (isRoot) gState.root = p;
}

#endif
