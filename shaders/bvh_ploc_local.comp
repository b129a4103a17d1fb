#version 460
// bvh_ploc_local: PLOC's first merges, chunk by chunk, in registers. The clusters are cut into
// chunks of kPlocLocalChunk in Morton order; each chunk's lanes (a subgroup of 8 on lavapipe, a
// part of a larger subgroup elsewhere) run PLOC's step among themselves: each finds its nearest
// neighbour within kPlocRadius places (subgroup shuffles instead of cluster reads), mutual pairs
// merge as bvh_ploc_merge merges them (the lower lane holds the parent, the upper one becomes a
// hole: the search skips holes, so it reaches fewer clusters as a chunk merges). The step
// repeats until a chunk of m clusters holds plocLocalKeep(m); where all mutual pairs would leave
// fewer, only the pair of least area merges (area, then lane: not plocTieKey's order, which
// only has to be one strict order). The survivors then go to the next cluster array at
// k * kPlocLocalChunk / 2 + their rank in chunk k (a ballot: no scan, no compaction pass).
// Why: the global iterations pay five dispatches and a compaction through memory for every
// cluster while the first quarter of the clusters merge; here the bottom of the tree is made
// from one read and one write per cluster. What it gives up: pairs across a chunk's edges wait
// for the global iterations, which makes the tree worse (docs/bvh.md).
// Assumes a subgroup's lanes are consecutive invocations (as plocSubgroupIndex does) and the
// subgroup size is a multiple of kPlocLocalChunk (the builder runs this pass only then).
// Input: clusters (texels), their build nodes and traversal-node counts (texels), state.count
// [param]. Outputs: interior nodes, parents, subtree node counts, next clusters, state.count and
// dispatch arguments of the other parity.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_KHR_shader_subgroup_shuffle_relative : require
#extension GL_KHR_shader_subgroup_vote : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
#define OSR_BUILD_TEXEL_BINDING kPlocBindingTexels
#include "lib/bvh_build_texels.glsl"
#define OSR_SUBTREE_NODES_BINDING kPlocBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"
#include "lib/bvh_ploc_steps.glsl"

// A lane's cluster and what a merge needs of its build node.
struct LocalCluster {
  PlocCluster c;
  float cost;
  uint triangleCount;
  uint flags;
  uint subtreeNodes;  // traversal nodes below (lib/bvh_subtree_nodes.glsl)
};

LocalCluster shuffleCluster(LocalCluster x, uint lane) {
  PlocCluster c = PlocCluster(subgroupShuffle(x.c.lo, lane), subgroupShuffle(x.c.hi, lane),
                              subgroupShuffle(x.c.node, lane), subgroupShuffle(x.c.firstLeaf, lane));
  return LocalCluster(c, subgroupShuffle(x.cost, lane), subgroupShuffle(x.triangleCount, lane),
                      subgroupShuffle(x.flags, lane), subgroupShuffle(x.subtreeNodes, lane));
}

BvhBuildNode buildNodeOf(LocalCluster x) {
  return BvhBuildNode(x.c.lo, x.cost, x.c.hi, x.triangleCount, kInvalidNode, kInvalidNode, kInvalidNode, x.flags);
}

// This lane's chunk's bits of a ballot (lanes `base` to base + kPlocLocalChunk - 1).
uint chunkBits(uvec4 ballot, uint base) {
  return (ballot[base >> 5u] >> (base & 31u)) & ((1u << kPlocLocalChunk) - 1u);
}

void main() {
  uint count = plocClusterCount();
  uint i = bvhBuildItem();  // every lane stays to the end: the chunk's shuffles read them all
  uint r = gl_SubgroupInvocationID % kPlocLocalChunk;  // == i % kPlocLocalChunk
  uint base = gl_SubgroupInvocationID - r;
  uint chunkStart = i - r;
  uint m = count > chunkStart ? min(kPlocLocalChunk, count - chunkStart) : 0u;
  uint keep = plocLocalKeep(m);
  if (i == 0u) {
    plocSetClusterCount(gPush.param ^ 1u, plocLocalCount(count), false);
    gState.clusterParity = gPush.param ^ 1u;
  }
  PlocCluster c = plocCluster(min(i, count - 1u));
  BvhBuildNode n = readNode(c.node);
  LocalCluster x = LocalCluster(c, n.cost, n.triangleCount, n.flags, subtreeNodesOf(c.node));
  bool live = r < m;
  uint alive = m;
  // Each step merges at least one pair while more than keep are alive (the least pair in the
  // chunk is mutual), and keep >= m / 2. Merged-away lanes stay as holes (no shuffles to close
  // up); the search reaches kPlocRadius lanes either way, alive ones only.
  while (subgroupAny(alive > keep)) {
    uint liveBits = chunkBits(subgroupBallot(live), base);
    // The nearest neighbour, ordered as bvh_ploc_nearest orders pairs. A lane computes its
    // unions with the lanes above it; the lanes below send theirs with it (one shuffle each).
    float best = uintBitsToFloat(0x7f800000u);
    uint bestTie = 0u, nearest = r;
    float areaAbove[kPlocRadius + 1u];
    for (uint d = 1u; d <= kPlocRadius; ++d) {
      PlocCluster o = x.c;
      o.lo = subgroupShuffleDown(x.c.lo, d);
      o.hi = subgroupShuffleDown(x.c.hi, d);
      uint j = r + d;
      areaAbove[d] = plocUnionArea(x.c, o);
      bool valid = live && j < kPlocLocalChunk && ((liveBits >> j) & 1u) != 0u;
      plocConsiderNeighbour(j, areaAbove[d], plocTieKey(d, chunkStart + r, chunkStart + j), valid, best, bestTie, nearest);
    }
    for (uint d = 1u; d <= kPlocRadius; ++d) {
      float a = subgroupShuffleUp(areaAbove[d], d);
      uint j = r - d;  // wraps below 0: then invalid
      bool valid = live && j < kPlocLocalChunk && ((liveBits >> j) & 1u) != 0u;
      plocConsiderNeighbour(j, a, plocTieKey(d, chunkStart + r, chunkStart + j), valid, best, bestTie, nearest);
    }
    // Shuffles outside any condition: in `a && shuffle(...)` the shuffle would run only on the
    // lanes where a holds, and read undefined values from the others.
    uint partnerNearest = subgroupShuffle(nearest, base + nearest);
    bool mutual = live && nearest != r && partnerNearest == r;
    bool lower = mutual && nearest > r;
    uint lowerBits = chunkBits(subgroupBallot(lower), base);
    // Where every mutual pair would leave fewer than keep: only the least (area, then lane).
    bool limit = alive - bitCount(lowerBits) < keep;
    uint leastArea = lower ? floatBitsToUint(best) : 0xffffffffu, leastLane = r;  // areas >= 0
    for (uint s = 1u; s < kPlocLocalChunk; s <<= 1u) {
      uint otherArea = subgroupShuffleXor(leastArea, s), otherLane = subgroupShuffleXor(leastLane, s);
      if (otherArea < leastArea || (otherArea == leastArea && otherLane < leastLane)) {
        leastArea = otherArea;
        leastLane = otherLane;
      }
    }
    bool merges = lower && alive > keep && (!limit || r == leastLane);
    LocalCluster partner = shuffleCluster(x, base + nearest);
    bool partnerChoseToMerge = subgroupShuffle(merges, base + nearest);
    bool partnerMerges = mutual && nearest < r && partnerChoseToMerge;
    // The pair's parent, as bvh_ploc_compact numbers it. Each lane sets its own node's parent: a
    // node made here was stored by this lane, and two invocations' stores to one word would be
    // unordered.
    uint p = plocParentIndex(x.c, partner.c);
    if (merges || partnerMerges) setParent(x.c.node, p);
    if (merges) {  // the parent, as bvh_ploc_merge makes it
      BvhBuildNode node = plocStoreParent(x.c.node, partner.c.node, p, buildNodeOf(x), buildNodeOf(partner),
                                          x.subtreeNodes + partner.subtreeNodes, false);
      uint below = subtreeNodesFrom(node.flags, x.subtreeNodes + partner.subtreeNodes);
      x = LocalCluster(plocUnion(x.c, partner.c, p), node.cost, node.triangleCount, node.flags, below);
    }
    live = live && !partnerMerges;
    alive = bitCount(chunkBits(subgroupBallot(live), base));
  }
  uint rank = bitCount(chunkBits(subgroupBallot(live), base) & ((1u << r) - 1u));
  if (live) plocStoreCluster(chunkStart / kPlocLocalChunk * (kPlocLocalChunk / 2u) + rank, x.c);
}
