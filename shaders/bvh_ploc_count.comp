#version 460
// bvh_ploc_count: per subgroup, the clusters that survive this iteration's merge (plocSurvives)
// and the mutual pairs, for bvh_ploc_plan's scans. Input: nearest (texels). Output: partials.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"

void main() {
  bool merges;
  uint j;
  uvec4 survivors = subgroupBallot(plocSurvives(bvhBuildItem(), plocClusterCount(), merges, j));
  uvec4 pairs = subgroupBallot(merges);
  if (subgroupElect()) {
    uint s = plocSubgroupIndex();
    gPartials[s] = subgroupBallotBitCount(survivors);
    gPartials[plocPairPartials() + s] = subgroupBallotBitCount(pairs);
  }
}
