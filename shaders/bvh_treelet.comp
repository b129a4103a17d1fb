#version 460
// bvh_treelet: treelet restructuring (Karras & Aila 2013, "Fast Parallel Construction of
// High-Quality Bounding Volume Hierarchies") of the nodes of one height (param), from the
// schedule of bvh_treelet_plan/scatter. Each node is first refitted from its children (whose
// subtrees earlier heights may have restructured), then grows a treelet of up to
// kTreeletLeaves leaves below it (always expanding the largest-area treelet leaf), finds by
// dynamic programming over all leaf subsets the topology of least SAH cost (leaf collapse
// included, as in the paper), and rewrites the treelet's interior nodes if that is cheaper.
// Nodes of one height own disjoint subtrees, so no two invocations touch the same node.
// With param2 = kTreeletCountNodes it also keeps each node's subtree node count (after PLOC,
// whose merges counted them; shared/bvh_build.h): the refitted root's and the rewritten nodes'.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
layout(constant_id = kTreeletSpecLeaves) const uint kTreeletLeaves = kTreeletMaxLeaves;
#include "lib/bvh_build_nodes.glsl"
// Reads through texels (lib/bvh_treelet_schedule.glsl): every node read here was written by an
// earlier dispatch (the subtrees below this height), but for the treelet root, which this
// invocation refits and keeps in registers.
#include "lib/bvh_treelet_schedule.glsl"
#define OSR_SUBTREE_NODES_BINDING kTreeletBindingSubtreeNodes
#include "lib/bvh_subtree_nodes.glsl"

// Whether this round keeps the subtree node counts (uniform: a push constant).
bool countsNodes() { return (gPush.param2 & kTreeletCountNodes) != 0u; }

const uint kSubsets = 1u << kTreeletMaxLeaves;

// Treelet leaf slots: the node and the fields that growing the treelet, the dynamic program and
// the rewrite need, kept so that each node is read once (memory latency, not arithmetic,
// dominates here).
struct Slot {
  uint node;
  vec3 lo;
  vec3 hi;
  float cost;
  uint triangles;
  uint flags;
  uint left;  // children, where node is interior
  uint right;
  uint subtreeNodes;  // where countsNodes()
};

Slot makeSlot(uint u, BvhBuildNode n) {
  Slot s;
  s.node = u;
  s.lo = n.lo;
  s.hi = n.hi;
  s.cost = n.cost;
  s.triangles = n.triangleCount;
  s.flags = n.flags;
  s.left = n.left;
  s.right = n.right;
  s.subtreeNodes = countsNodes() ? subtreeNodesOf(u) : 0u;
  return s;
}
Slot readSlot(uint u) { return makeSlot(u, readNode(u)); }

const uint kCollapseBit = 0x80000000u;  // in gSplit[]: the subset becomes one leaf

// The treelet's leaf slots and the dynamic program's tables: per subset of the slots, the least
// SAH cost of a tree over it and the first part of its root split (kCollapseBit: the subset
// becomes one leaf).
Slot gSlots[kTreeletMaxLeaves];
float gCost[kSubsets];
uint gSplit[kSubsets];

// The dynamic program over all subsets of the kTreeletLeaves slots (mayCollapseAll: the full set
// may become one leaf, which the tree's root may not). These loops define it; treeletDp (generated
// by tools/gen_treelet_dp.py, which says why) runs the same program unrolled for the treelet
// sizes it covers and these loops for larger ones: on lavapipe the tables here live in scratch
// memory, read with a scalar load per SIMD lane.
void treeletDpLoop(bool mayCollapseAll) {
  const uint full = (1u << kTreeletLeaves) - 1u;
  // Subsets in increasing order: every proper subset of s is smaller than s. The trip counts are
  // the same on every lane: on lavapipe that keeps the loops uniform.
  for (uint s = 1u; s <= full; ++s) {
    if (bitCount(s) == 1) {
      gCost[s] = gSlots[findLSB(s)].cost;
      gSplit[s] = 0u;
      continue;
    }
    vec3 slo = vec3(3.0e38), shi = vec3(-3.0e38);
    uint tris = 0u;
    for (uint k = 0u; k < kTreeletLeaves; ++k)
      if ((s & (1u << k)) != 0u) {
        slo = min(slo, gSlots[k].lo);
        shi = max(shi, gSlots[k].hi);
        tris += gSlots[k].triangles;
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
      float c = gCost[p] + gCost[s ^ p];
      if (c < best) {
        best = c;
        bestP = p;
      }
      if (q == 0u) break;
    }
    // Same rule as refitNode: collapse when not more costly.
    float interiorCost = kSahNodeCost * area + best;
    float leafCost = kSahTriangleCost * area * float(tris);
    bool collapse = tris <= kBvhMaxLeafTriangles && (s != full || mayCollapseAll) && leafCost <= interiorCost;
    gCost[s] = collapse ? leafCost : interiorCost;
    gSplit[s] = bestP | (collapse ? kCollapseBit : 0u);
  }
}
#include "bvh_treelet_dp.glsl"

// root: an interior node refitted from its children, rn: its fields; l, r: its children's.
void restructure(uint root, BvhBuildNode rn, BvhBuildNode l, BvhBuildNode r) {
  uint interior[kTreeletMaxLeaves - 1u];
  gSlots[0] = makeSlot(rn.left, l);
  gSlots[1] = makeSlot(rn.right, r);
  interior[0] = root;
  uint nl = 2u, ni = 1u;
  while (nl < kTreeletLeaves) {
    int best = -1;
    float bestArea = -1.0;
    for (uint k = 0u; k < nl; ++k) {
      float a = boxArea(gSlots[k].lo, gSlots[k].hi);
      if (!isLeafNode(gSlots[k].node) && a > bestArea) {
        best = int(k);
        bestArea = a;
      }
    }
    if (best < 0) break;
    Slot expanded = gSlots[best];
    interior[ni++] = expanded.node;
    gSlots[best] = readSlot(expanded.left);
    gSlots[nl++] = readSlot(expanded.right);
  }
  // A subtree with fewer leaves than a treelet (only below minTriangles < kTreeletLeaves) is
  // left as it is, so that the dynamic program runs the same code on every lane.
  if (nl < kTreeletLeaves) return;
  const uint full = (1u << kTreeletLeaves) - 1u;

  treeletDp(root != 0u);
  // Keep the old topology unless the new one is measurably cheaper (ties would churn).
  if (!(gCost[full] < rn.cost * 0.9999)) return;

  // Assign subsets to the treelet's interior nodes top-down: node interior[k] gets subset
  // subsetOf[k]; its children are leaf slots or interior nodes assigned after it. A child is
  // recorded as slot index j (< kTreeletMaxLeaves) or kTreeletMaxLeaves + interior index.
  uint subsetOf[kTreeletMaxLeaves - 1u];
  uint childOf[kTreeletMaxLeaves - 1u][2];
  uint parentOf[kTreeletMaxLeaves - 1u];
  subsetOf[0] = full;
  parentOf[0] = rn.parent;
  uint next = 1u;
  for (uint k = 0u; k < ni; ++k) {
    uint s = subsetOf[k];
    uint p = gSplit[s] & ~kCollapseBit;
    uint parts[2] = uint[2](p, s ^ p);
    for (int c = 0; c < 2; ++c) {
      if (bitCount(parts[c]) == 1) {
        uint j = uint(findLSB(parts[c]));
        childOf[k][c] = j;
        setParent(gSlots[j].node, interior[k]);
      } else {
        childOf[k][c] = kTreeletMaxLeaves + next;
        subsetOf[next] = parts[c];
        parentOf[next] = interior[k];
        ++next;
      }
    }
  }
  // Write each interior node once, bottom-up (children were assigned after their parents):
  // bounds, count and cost from the subset, heights from the children.
  uint flagsOf[kTreeletMaxLeaves - 1u];
  uint subtreeNodesOfInterior[kTreeletMaxLeaves - 1u];
  for (int k = int(ni) - 1; k >= 0; --k) {
    uint s = subsetOf[k];
    BvhBuildNode n;
    n.lo = vec3(3.0e38);
    n.hi = vec3(-3.0e38);
    n.triangleCount = 0u;
    for (uint j = 0u; j < kTreeletLeaves; ++j)
      if ((s & (1u << j)) != 0u) {
        n.lo = min(n.lo, gSlots[j].lo);
        n.hi = max(n.hi, gSlots[j].hi);
        n.triangleCount += gSlots[j].triangles;
      }
    n.cost = gCost[s];
    uint height = 0u, traversalHeight = 0u, below = 0u;
    uint ids[2];
    for (int c = 0; c < 2; ++c) {
      uint child = childOf[k][c];
      uint childFlags = child < kTreeletMaxLeaves ? gSlots[child].flags : flagsOf[child - kTreeletMaxLeaves];
      below += child < kTreeletMaxLeaves ? gSlots[child].subtreeNodes : subtreeNodesOfInterior[child - kTreeletMaxLeaves];
      ids[c] = child < kTreeletMaxLeaves ? gSlots[child].node : interior[child - kTreeletMaxLeaves];
      height = max(height, childFlags & kHeightMask);
      traversalHeight = max(traversalHeight, (childFlags >> kTraversalHeightShift) & kHeightMask);
    }
    bool collapse = (gSplit[s] & kCollapseBit) != 0u;
    n.flags = (collapse ? kFlagCollapsed : 0u) | ((collapse ? 0u : traversalHeight + 1u) << kTraversalHeightShift) |
              (height + 1u);
    n.left = ids[0];
    n.right = ids[1];
    n.parent = parentOf[k];
    flagsOf[k] = n.flags;
    subtreeNodesOfInterior[k] = subtreeNodesFrom(n.flags, below);
    storeInterior(interior[k], n);
    if (countsNodes()) gSubtreeNodes[interior[k]] = subtreeNodesOfInterior[k];
  }
}

void main() {
  LevelList level = gLevels[gPush.param];
  uint i = bvhBuildItem();
  if (i >= level.count) return;
  uint node = gNodeList[level.offset + i];
  BvhBuildNode n = readInterior(node);
  BvhBuildNode l = readNode(n.left), r = readNode(n.right);
  n = refitNode(n, l, r, node == 0u);
  storeInterior(node, n);
  if (countsNodes()) gSubtreeNodes[node] = subtreeNodesFrom(n.flags, subtreeNodesOf(n.left) + subtreeNodesOf(n.right));
  restructure(node, n, l, r);
}
