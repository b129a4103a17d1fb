#version 460
// bvh_treelet: treelet restructuring (Karras & Aila 2013, "Fast Parallel Construction of
// High-Quality Bounding Volume Hierarchies") of the nodes of one height (param), from the
// schedule of bvh_treelet_plan/scatter. Each node is first refitted from its children (whose
// subtrees earlier heights may have restructured), then grows a treelet of up to
// kTreeletLeaves leaves below it (always expanding the largest-area treelet leaf), finds by
// dynamic programming over all leaf subsets the topology of least SAH cost (leaf collapse
// included, as in the paper), and rewrites the treelet's interior nodes if that is cheaper.
// Nodes of one height own disjoint subtrees, so no two invocations touch the same node.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
layout(constant_id = kTreeletSpecLeaves) const uint kTreeletLeaves = kTreeletMaxLeaves;
layout(push_constant) uniform PushBlock { BuildPush gPush; };
#include "lib/bvh_build_nodes.glsl"
#include "lib/bvh_treelet_schedule.glsl"

const uint kSubsets = 1u << kTreeletMaxLeaves;

void restructure(uint root) {
  uint leaves[kTreeletMaxLeaves];
  float leafArea[kTreeletMaxLeaves];
  uint interior[kTreeletMaxLeaves - 1u];
  BvhBuildNode rn = gInterior[root];
  leaves[0] = rn.left;
  leaves[1] = rn.right;
  BvhBuildNode l0 = loadNode(rn.left), l1 = loadNode(rn.right);
  leafArea[0] = boxArea(l0.lo, l0.hi);
  leafArea[1] = boxArea(l1.lo, l1.hi);
  interior[0] = root;
  uint nl = 2u, ni = 1u;
  while (nl < kTreeletLeaves) {
    int best = -1;
    float bestArea = -1.0;
    for (uint k = 0u; k < nl; ++k)
      if (!isLeafNode(leaves[k]) && leafArea[k] > bestArea) {
        best = int(k);
        bestArea = leafArea[k];
      }
    if (best < 0) break;
    BvhBuildNode e = gInterior[leaves[best]];
    interior[ni++] = leaves[best];
    BvhBuildNode a = loadNode(e.left), b = loadNode(e.right);
    leaves[best] = e.left;
    leafArea[best] = boxArea(a.lo, a.hi);
    leaves[nl] = e.right;
    leafArea[nl] = boxArea(b.lo, b.hi);
    ++nl;
  }
  if (nl < 3u) return;  // two leaves have one topology only

  vec3 lo[kTreeletMaxLeaves], hi[kTreeletMaxLeaves];
  float leafCost[kTreeletMaxLeaves];
  uint leafTris[kTreeletMaxLeaves];
  for (uint k = 0u; k < nl; ++k) {
    BvhBuildNode n = loadNode(leaves[k]);
    lo[k] = n.lo;
    hi[k] = n.hi;
    leafCost[k] = n.cost;
    leafTris[k] = n.triangleCount;
  }
  float cost[kSubsets];
  uint split[kSubsets];
  uint full = (1u << nl) - 1u;
  // Subsets in increasing order: every proper subset of s is smaller than s.
  for (uint s = 1u; s <= full; ++s) {
    if (bitCount(s) == 1) {
      cost[s] = leafCost[findLSB(s)];
      split[s] = 0u;
      continue;
    }
    vec3 slo = vec3(3.0e38), shi = vec3(-3.0e38);
    uint tris = 0u;
    for (uint k = 0u; k < nl; ++k)
      if ((s & (1u << k)) != 0u) {
        slo = min(slo, lo[k]);
        shi = max(shi, hi[k]);
        tris += leafTris[k];
      }
    float area = boxArea(slo, shi);
    // Each unordered partition once: p = the lowest member of s plus any proper subset q of
    // the rest (q = rest itself would make p = s), enumerated by the usual (q - 1) & rest walk.
    uint lowest = s & (~s + 1u);
    uint rest = s ^ lowest;
    float best = 3.0e38;
    uint bestP = 0u;
    for (uint q = (rest - 1u) & rest;; q = (q - 1u) & rest) {
      uint p = lowest | q;
      float c = cost[p] + cost[s ^ p];
      if (c < best) {
        best = c;
        bestP = p;
      }
      if (q == 0u) break;
    }
    float c = kSahNodeCost * area + best;
    bool canCollapse = tris <= kBvhMaxLeafTriangles && !(s == full && root == 0u);
    if (canCollapse) c = min(c, kSahTriangleCost * area * float(tris));
    cost[s] = c;
    split[s] = bestP;
  }
  // Keep the old topology unless the new one is measurably cheaper (ties would churn).
  if (!(cost[full] < rn.cost * 0.9999)) return;

  // Assign subsets to the treelet's interior nodes top-down: node interior[k] gets subset
  // subsetOf[k]; its children are leaves or interior nodes assigned after it.
  uint subsetOf[kTreeletMaxLeaves - 1u];
  subsetOf[0] = full;
  uint next = 1u;
  for (uint k = 0u; k < ni; ++k) {
    uint s = subsetOf[k];
    uint node = interior[k];
    uint parts[2] = uint[2](split[s], s ^ split[s]);
    uint child[2];
    for (int c = 0; c < 2; ++c) {
      if (bitCount(parts[c]) == 1) {
        child[c] = leaves[findLSB(parts[c])];
      } else {
        child[c] = interior[next];
        subsetOf[next] = parts[c];
        ++next;
      }
      setParent(child[c], node);
    }
    gInterior[node].left = child[0];
    gInterior[node].right = child[1];
  }
  // Bounds, costs and heights bottom-up: children were assigned after their parents.
  for (int k = int(ni) - 1; k >= 0; --k) refitStored(interior[k]);
}

void main() {
  TreeletLevel level = gLevels[gPush.param];
  uint i = gl_GlobalInvocationID.x;
  if (i >= level.count) return;
  uint node = gNodeList[level.offset + i];
  refitStored(node);
  restructure(node);
}
