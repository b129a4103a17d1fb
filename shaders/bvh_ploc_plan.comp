#version 460
// bvh_ploc_plan: one workgroup. Turns bvh_ploc_count's per-subgroup counts of survivors and of
// pairs into each subgroup's first place in the next cluster array and in the pair list
// (exclusive scans: each invocation scans a run of subgroups, after the totals of the runs
// before it), and sets the next iteration's cluster count and dispatch (no group once one
// cluster is left) and this one's pair count and dispatch. Runs, not one serial loop: llvmpipe
// ends any loop after 65535 iterations. Input/output: partials, state.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;  // the other passes' subgroup size
#include "lib/bvh_ploc.glsl"

shared uvec2 sRunTotals[kWorkgroupSize];

void main() {
  uint count = plocClusterCount();
  uint t = gl_LocalInvocationIndex;
  // The subgroups of bvh_ploc_count's dispatch: whole workgroups of kWorkgroupSize invocations.
  uint subgroups = (count + kWorkgroupSize - 1u) / kWorkgroupSize * (kWorkgroupSize / gl_SubgroupSize);
  uint run = (subgroups + kWorkgroupSize - 1u) / kWorkgroupSize;
  uint first = min(t * run, subgroups), end = min(first + run, subgroups);
  // Whether this iteration ran (its dispatch had groups); else it leaves everything as it was.
  bool merged = (gPush.param == 0u ? gState.args0.x : gState.args1.x) != 0u;
  uint pairBase = plocPairPartials();
  uvec2 total = uvec2(0u);  // survivors, pairs
  for (uint g = first; merged && g < end; ++g) total += uvec2(gPartials[g], gPartials[pairBase + g]);
  sRunTotals[t] = total;
  barrier();
  uvec2 before = uvec2(0u), sum = uvec2(0u);
  for (uint k = 0u; k < kWorkgroupSize; ++k) {
    before += k < t ? sRunTotals[k] : uvec2(0u);
    sum += sRunTotals[k];
  }
  for (uint g = first; merged && g < end; ++g) {
    uvec2 c = uvec2(gPartials[g], gPartials[pairBase + g]);
    gPartials[g] = before.x;
    gPartials[pairBase + g] = before.y;
    before += c;
  }
  if (t != 0u) return;
  uint survivors = merged ? sum.x : count;
  if (merged) {
    gState.iterations += 1u;
    gState.clusterParity = gPush.param ^ 1u;
  }
  plocSetClusterCount(gPush.param ^ 1u, survivors, true);
  gState.pairs = sum.y;
  gState.pairArgs = DispatchArgs((sum.y + kWorkgroupSize - 1u) / kWorkgroupSize, 1u, 1u);
}
