#version 460
// bvh_ploc_nearest: for each cluster, the cluster within kPlocRadius places whose union with it
// has the least surface area. Pairs are ordered by that area, then by their distance in Morton
// order, then by a hash of the pair, then by the lower index: one strict order of pairs that
// both clusters of a pair see, so the least pair is always mutual and every iteration merges.
// Ties matter where areas are equal (congruent triangles of a tessellation, which boxes
// quantized to 16 bits made common): broken by index alone, a run of equals merges one pair per
// iteration (the 1M-triangle bench mesh then took 122 iterations and its tree passed
// kBvhMaxDepth). A fixed trip count, lanes past the ends masked: every lane runs the same steps.
// Input: clusters (texels). Output: nearest.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
#include "lib/bvh_ploc.glsl"

void main() {
  uint count = plocClusterCount();
  uint i = bvhBuildItem();
  if (i >= count) return;
  PlocCluster self = plocCluster(i);
  float best = uintBitsToFloat(0x7f800000u);  // +inf: any neighbour beats it
  uint bestHash = 0u;
  uint nearest = i;
  for (uint k = 0u; k <= 2u * kPlocRadius; ++k) {
    uint j = i + k - kPlocRadius;  // wraps below 0: then past count
    bool valid = j < count && j != i;
    float a = plocUnionArea(self, plocCluster(valid ? j : i));
    uint h = plocTieKey(uint(abs(int(k) - int(kPlocRadius))), i, j);
    if (valid && (a < best || (a == best && h < bestHash))) {
      best = a;
      bestHash = h;
      nearest = j;
    }
  }
  gNearest[i] = nearest;
}
