// The PLOC passes' bindings and helpers (shared/bvh_build.h, "PLOC"). The includer has included
// lib/bvh_build_arrays.glsl.
#ifndef OSR_BVH_PLOC_GLSL
#define OSR_BVH_PLOC_GLSL
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "lib/bvh_build_refit.glsl"

layout(binding = kPlocBindingClusterTexels) uniform usamplerBuffer gClusterTexels;
layout(std430, binding = kPlocBindingNextClusters) writeonly buffer NextClusters { uvec4 gNextClusters[]; };
// coherent: bvh_ploc_tail reads what other invocations of its workgroup wrote (after a barrier).
layout(std430, binding = kPlocBindingNearest) coherent buffer Nearest { uint gNearest[]; };
layout(binding = kPlocBindingNearestTexels) uniform usamplerBuffer gNearestTexels;
layout(std430, binding = kPlocBindingPartials) buffer Partials { uint gPartials[]; };
layout(std430, binding = kPlocBindingState) buffer State { PlocState gState; };
// A mutual pair: (lower cluster's node, upper cluster's node, the parent's index, unused).
layout(std430, binding = kPlocBindingPairs) buffer Pairs { uvec4 gPairs[]; };

// Where the per-subgroup pair counts start in partials.
uint plocPairPartials() { return gPush.triangleCount + kWorkgroupSize; }

// Clusters at the start of this iteration (push param: its parity).
uint plocClusterCount() { return gState.count[gPush.param]; }

// A cluster: its box, its build node and its first leaf (lowest sorted index below it), in two
// texels: (lo, node), (hi, firstLeaf).
struct PlocCluster {
  vec3 lo;
  vec3 hi;
  uint node;
  uint firstLeaf;
};

// Cluster i (through the texel view: a gather on lavapipe; the neighbours a lane reads lie next
// to each other in memory).
PlocCluster plocCluster(uint i) {
  uvec4 a = texelFetch(gClusterTexels, int(2u * i)), b = texelFetch(gClusterTexels, int(2u * i + 1u));
  return PlocCluster(uintBitsToFloat(a.xyz), uintBitsToFloat(b.xyz), a.w, b.w);
}
void plocStoreCluster(uint i, PlocCluster c) {
  gNextClusters[2u * i] = uvec4(floatBitsToUint(c.lo), c.node);
  gNextClusters[2u * i + 1u] = uvec4(floatBitsToUint(c.hi), c.firstLeaf);
}

// The cluster of the union of two clusters, holding `node`.
PlocCluster plocUnion(PlocCluster a, PlocCluster b, uint node) {
  return PlocCluster(min(a.lo, b.lo), max(a.hi, b.hi), node, min(a.firstLeaf, b.firstLeaf));
}

// Half the surface area of the union of two clusters' boxes; past 3e38 (NaN, infinite
// coordinates) 3e38. precise: ties are compared with ==, and the passes that search
// (bvh_ploc_nearest, bvh_ploc_tail, bvh_ploc_local) must see the same bits, however a compiler
// would otherwise fuse the products and sums in each.
float plocUnionArea(PlocCluster a, PlocCluster b) {
  vec3 d = max(a.hi, b.hi) - min(a.lo, b.lo);
  precise float area = d.x * d.y + d.y * d.z + d.z * d.x;
  return area < 3.0e38 ? area : 3.0e38;
}

// A hash of the unordered pair {i, j} (a 32-bit integer mix).
uint pairHash(uint i, uint j) {
  uint h = min(i, j) * 0x9e3779b1u ^ max(i, j) * 0x85ebca77u;
  h ^= h >> 15u;
  h *= 0x2c1b3c6du;
  h ^= h >> 12u;
  return h;
}
// What orders two pairs of equal union area (bvh_ploc_nearest): the nearer in Morton order
// (`distance` places apart), then the hash of the pair. Both clusters of a pair compute it alike.
uint plocTieKey(uint distance, uint i, uint j) { return (distance << 24u) | (pairHash(i, j) >> 8u); }

// Sets the clusters an iteration of parity `parity` starts from, and its per-cluster dispatch: no
// group once one cluster is left (the tree is done) or, where `tail`, once no more than
// state.tailClusters are (bvh_ploc_tail finishes). One invocation calls it (bvh_ploc_plan for
// the next iteration, bvh_ploc_local for the first, which always runs).
void plocSetClusterCount(uint parity, uint count, bool tail) {
  gState.count[parity] = count;
  bool runs = count > 1u && (!tail || count > gState.tailClusters);
  DispatchArgs args = DispatchArgs(runs ? (count + kWorkgroupSize - 1u) / kWorkgroupSize : 0u, 1u, 1u);
  if (parity == 0u) {
    gState.args0 = args;
  } else {
    gState.args1 = args;
  }
}

// Cluster i's nearest neighbour (bvh_ploc_nearest's, read by later dispatches: a gather).
uint plocNearest(uint i) { return texelFetch(gNearestTexels, int(i)).x; }

// Whether cluster i, whose nearest neighbour is j, and j's is nearestOfJ, survives this
// iteration's merge (it is in range, and has no mutual nearest neighbour or is the lower of a
// mutual pair), and whether it merges (the lower of a pair, with cluster j).
bool plocSurvivesGiven(uint i, uint count, uint j, uint nearestOfJ, out bool merges) {
  bool mutual = i < count && nearestOfJ == i;
  merges = mutual && i < j;
  return i < count && (!mutual || i < j);
}
// plocSurvivesGiven with bvh_ploc_nearest's results. Every lane reads: lanes past count read the
// last cluster's.
bool plocSurvives(uint i, uint count, out bool merges, out uint partner) {
  uint j = plocNearest(min(i, count - 1u));
  partner = j;
  return plocSurvivesGiven(i, count, j, plocNearest(j), merges);
}

// The index of the parent of merging clusters a and b (shared/bvh_build.h: the later first leaf
// of the two, minus 1).
uint plocParentIndex(PlocCluster a, PlocCluster b) { return max(a.firstLeaf, b.firstLeaf) - 1u; }

// Keeps neighbour j (union area a, tie key `tie`) if it is valid and orders before the best so
// far, as bvh_ploc_nearest orders pairs.
void plocConsiderNeighbour(uint j, float a, uint tie, bool valid, inout float best, inout uint bestTie, inout uint nearest) {
  if (valid && (a < best || (a == best && tie < bestTie))) {
    best = a;
    bestTie = tie;
    nearest = j;
  }
}

// This subgroup's place among the dispatch's subgroups, which bvh_ploc_count's survivor counts
// and bvh_ploc_compact's offsets are kept by (per subgroup: no barrier, no shared memory, which
// lavapipe runs slowly). Assumes, as lavapipe and the GPUs we know lay them out, that a
// subgroup's lanes are consecutive invocations; the dispatch is one row (bvh_ploc_plan).
uint plocSubgroupIndex() {
  return (gl_WorkGroupID.x * kWorkgroupSize) / gl_SubgroupSize + gl_SubgroupID;
}

#endif
