#version 460
// bvh_ploc_tail: one workgroup runs PLOC's last iterations, from the clusters the global
// iterations left (at most state.tailClusters where they stopped, at most param2, its capacity)
// down to the root, with barriers between the steps instead of dispatches. Each iteration is
// the global one step by step, so the tree is the same bit for bit: every cluster's nearest
// neighbour (plocNearestNeighbour); each invocation counts the survivors and pairs of its run
// of clusters and a workgroup scan places them; each invocation then moves its survivors to the
// other array in order and makes its pairs' parents (plocMergePair). Why: below a few thousand
// clusters an iteration is a few hundred merges, and the five dispatches it takes cost more
// than its work (most of the iterations of a large mesh; docs/bvh.md). Its clusters
// live in its own scratch (tail clusters: two arrays of param2), copied in first from the
// cluster array that state.clusterParity names; nodes made here are read back through storage
// (coherent), never through texels. Leaves state.count[param] = 1 (param: the parity the host
// reads) and adds its iterations to state.iterations; does nothing where one cluster is left,
// or more than param2 (the host then records more global iterations).
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"
layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"
#define OSR_SUBTREE_NODES_BINDING kPlocBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"
#include "lib/bvh_ploc_steps.glsl"
layout(std430, binding = kPlocBindingTailClusters) coherent buffer TailClusters { uvec4 gTail[]; };
layout(binding = kPlocBindingClusterTexels1) uniform usamplerBuffer gClusterTexels1;

uint gSource = 0u;  // which tail array holds this iteration's clusters

PlocCluster tailCluster(uint array, uint i) {
  uint at = 2u * (array * gPush.param2 + i);
  uvec4 a = gTail[at], b = gTail[at + 1u];
  return PlocCluster(uintBitsToFloat(a.xyz), uintBitsToFloat(b.xyz), a.w, b.w);
}
void storeTailCluster(uint array, uint i, PlocCluster c) {
  uint at = 2u * (array * gPush.param2 + i);
  gTail[at] = uvec4(floatBitsToUint(c.lo), c.node);
  gTail[at + 1u] = uvec4(floatBitsToUint(c.hi), c.firstLeaf);
}

PlocCluster plocSearchCluster(uint i) { return tailCluster(gSource, i); }
BvhBuildNode plocChildNode(uint u) { return loadNode(u); }
uint plocChildSubtreeNodes(uint u) {
  uint ic = interiorCount();
  uint count = gSubtreeNodes[min(u, ic - 1u)];
  return u < ic ? count : 0u;
}

// Everything written before is visible to the whole workgroup after it.
void workgroupSync() {
  memoryBarrierBuffer();
  barrier();
}

// An exclusive scan of `mine` over the workgroup (invocation order); returns the sum before this
// invocation, and the total in `total`.
shared uvec2 sSubgroupTotals[kWorkgroupSize];
uvec2 workgroupExclusiveAdd(uvec2 mine, out uvec2 total) {
  uvec2 before = subgroupExclusiveAdd(mine);
  uvec2 sum = subgroupAdd(mine);
  if (subgroupElect()) sSubgroupTotals[gl_SubgroupID] = sum;
  barrier();
  total = uvec2(0u);
  for (uint s = 0u; s < gl_NumSubgroups; ++s) {
    uvec2 t = sSubgroupTotals[s];
    before += s < gl_SubgroupID ? t : uvec2(0u);
    total += t;
  }
  barrier();  // before the next scan overwrites the totals
  return before;
}

void main() {
  // Invocations in subgroup order, which the scan follows (workgroupExclusiveAdd): runs of
  // clusters, and so survivors, stay in order whatever the local index's layout.
  uint t = gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
  uint count = gState.count[gPush.param];
  if (count <= 1u || count > gPush.param2) return;  // uniform: the whole workgroup leaves
  uint from = gState.clusterParity;
  for (uint i = t; i < count; i += kWorkgroupSize) {
    uvec4 a0 = texelFetch(gClusterTexels, int(2u * i));
    uvec4 b0 = texelFetch(gClusterTexels, int(2u * i + 1u));
    uvec4 a1 = texelFetch(gClusterTexels1, int(2u * i));
    uvec4 b1 = texelFetch(gClusterTexels1, int(2u * i + 1u));
    uvec4 a = from == 0u ? a0 : a1, b = from == 0u ? b0 : b1;
    storeTailCluster(0u, i, PlocCluster(uintBitsToFloat(a.xyz), uintBitsToFloat(b.xyz), a.w, b.w));
  }
  workgroupSync();
  uint iterations = 0u;
  // Each iteration merges at least one pair: at most count - 1 of them. The bound only guards
  // against corrupt state (a device would hang, not stop as llvmpipe's loop limit does): the
  // host then sees more than one cluster left and rebuilds.
  while (count > 1u && iterations < gPush.param2) {
    bool isRoot = count == 2u;
    for (uint i = t; i < count; i += kWorkgroupSize) gNearest[i] = plocNearestNeighbour(i, count);
    workgroupSync();
    // This invocation's run of clusters: survivors stay in order across the runs.
    uint run = (count + kWorkgroupSize - 1u) / kWorkgroupSize;
    uint first = min(t * run, count), end = min(first + run, count);
    uvec2 mine = uvec2(0u);  // survivors, pairs
    for (uint i = first; i < end; ++i) {
      bool merges;
      uint j = gNearest[i];
      bool survives = plocSurvivesGiven(i, count, j, gNearest[j], merges);
      mine += uvec2(survives ? 1u : 0u, merges ? 1u : 0u);
    }
    uvec2 total;
    uint at = workgroupExclusiveAdd(mine, total).x;
    for (uint i = first; i < end; ++i) {
      bool merges;
      uint j = gNearest[i];
      bool survives = plocSurvivesGiven(i, count, j, gNearest[j], merges);
      PlocCluster a = tailCluster(gSource, i);
      if (merges) {
        PlocCluster b = tailCluster(gSource, j);
        uint node = plocParentIndex(a, b);
        plocMergePair(a.node, b.node, node, isRoot);
        // The root's cluster holds 0, as in bvh_ploc_compact.
        a = plocUnion(a, b, isRoot ? 0u : node);
      }
      if (survives) storeTailCluster(gSource ^ 1u, at++, a);
    }
    workgroupSync();
    count = total.x;
    gSource ^= 1u;
    ++iterations;
  }
  if (t == 0u) {
    gState.count[gPush.param] = 1u;
    gState.iterations += iterations;
  }
}
