#version 460
// bvh_ploc_compact: the clusters that survive this iteration's merge, to the next cluster array
// in the same order (Morton order keeps neighbours near), and the mutual pairs to the pair list.
// The lower cluster of a pair becomes the cluster of the pair's parent (the union of their
// boxes), whose index follows from the leaves below it (shared/bvh_build.h): no counter is
// taken. Inputs: clusters, nearest (texels), partials (scanned by bvh_ploc_plan).
// Outputs: next clusters, pairs.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"

void main() {
  uint count = plocClusterCount();
  uint i = bvhBuildItem();
  bool merges;
  uint j;
  bool survives = plocSurvives(i, count, merges, j);
  uvec4 survivorBallot = subgroupBallot(survives), pairBallot = subgroupBallot(merges);
  uint s = plocSubgroupIndex();
  uint at = gPartials[s] + subgroupBallotExclusiveBitCount(survivorBallot);
  uint pairAt = gPartials[plocPairPartials() + s] + subgroupBallotExclusiveBitCount(pairBallot);
  PlocCluster a = plocCluster(min(i, count - 1u)), b = plocCluster(j);
  uint node = plocParentIndex(a, b);
  // The root's cluster (the last pair's) holds index 0, where bvh_ploc_root moves the root.
  if (survives) plocStoreCluster(at, merges ? plocUnion(a, b, count == 2u ? 0u : node) : a);
  if (merges) gPairs[pairAt] = uvec4(a.node, b.node, node, 0u);
}
