#version 460
// bvh_emit_nodes: the traversal nodes (shared/bvh.h), exact (BvhNode) and/or quantized
// (BvhTraversalNode, shared/bvh_quantize.h) as kForms asks, in depth-first order, and where
// each leaf's triangles go. One indirect dispatch per depth (param), one invocation per
// traversal node of that depth (the root alone at depth 0, position 0). A node at position p:
//   - puts its child a at p + 1 and its child b at p + 1 + (a's traversal nodes, from
//     bvh_subtree_count) where those children are traversal nodes, and appends them to the next
//     depth's list (sizing that depth's dispatch);
//   - turns each child that is a leaf or a collapsed subtree into a leaf. Leaf entries are in
//     depth-first order too: a node's subtree's start at its leaf base (the root's 0), child a's
//     there, child b's after a's triangles, so the triangles a walk tests lie near each other;
//     bvh_emit_leaves copies them there (slots[build node] = bvhEmitSlot(a's first entry, a's
//     count), or b's first entry and 0 where a is a node). info.leafCounter sums the leaf
//     triangles, for the host's check;
//   - stores the forms of itself that kForms asks for at p.
// A walk that descends to child a finds it next to its parent, and every subtree is one run of
// nodes. Appends and the leaf count take one atomic per workgroup (subgroup totals meet in
// shared memory): one counter that every subgroup hits moves its cache line between lavapipe's
// two threads.
// Inputs: build nodes, subtreeNodes, positions[root] = leafBases[root] = 0, the schedule's depth
// 0, info.leafCounter = 0. Specialized (shared/bvh_build.h): kForms, which forms to write;
// kSingleTriangle, a build of one triangle (one invocation writes the root).
// Outputs: nodes, traversal nodes (as kForms says), slots, positions, leafBases.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "lib/bvh_build_arrays.glsl"
#include "shared/bvh_quantize.h"

layout(local_size_x = kWorkgroupSize) in;
layout(constant_id = kEmitSpecForms) const uint kForms = kEmitExactNodes | kEmitQuantizedNodes;
layout(constant_id = kEmitSpecSingleTriangle) const bool kSingleTriangle = false;
layout(std430, binding = kEmitBindingInfo) buffer Info { BvhBuildInfo gInfo; };
layout(std430, binding = kEmitBindingSlots) writeonly buffer Slots { uint gSlots[]; };
layout(std430, binding = kEmitBindingPositions) buffer Positions { uint gPositions[]; };
layout(std430, binding = kEmitBindingSubtreeNodes) readonly buffer SubtreeNodes { uint gSubtreeNodes[]; };
layout(std430, binding = kEmitBindingSchedule) coherent buffer Schedule {
  LevelList gLevels[kEmitMaxLevels];
  DispatchArgs gArgs[kEmitMaxLevels];
};
layout(std430, binding = kEmitBindingLevelNodes) buffer LevelNodes { uint gLevelNodes[]; };
layout(std430, binding = kEmitBindingLeafBases) buffer LeafBases { uint gLeafBases[]; };
#define OSR_BUILD_TEXEL_BINDING kEmitBindingTexels
#include "lib/bvh_build_texels.glsl"

bool becomesLeaf(uint u, BvhBuildNode n) {
  return u >= interiorCount() || (n.flags & kFlagCollapsed) != 0u;
}

uint leafRef(BvhBuildNode n, uint slot) {
  return kBvhLeafFlag | (n.triangleCount << kBvhLeafCountShift) | slot;
}

// Per workgroup, one atomic on each counter: x leaf triangles (only counted), y next-depth list
// entries. Called in uniform control flow by the whole workgroup; returns this invocation's
// first of each.
shared uvec2 sSubgroupFirst[kWorkgroupSize];  // per subgroup: its first entries
shared uint sListEnd;                          // the workgroup's end in the next depth's list
uvec2 allocate(uvec2 counts, uint nextDepth) {
  uvec2 offset = subgroupExclusiveAdd(counts);
  uvec2 total = subgroupAdd(counts);
  if (subgroupElect()) sSubgroupFirst[gl_SubgroupID] = total;
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    uvec2 sum = uvec2(0u);
    for (uint s = 0u; s < gl_NumSubgroups; ++s) {
      uvec2 t = sSubgroupFirst[s];
      sSubgroupFirst[s] = sum;
      sum += t;
    }
    uvec2 base = uvec2(sum.x == 0u ? 0u : atomicAdd(gInfo.leafCounter, sum.x),
                       sum.y == 0u ? 0u : atomicAdd(gLevels[nextDepth].count, sum.y));
    for (uint s = 0u; s < gl_NumSubgroups; ++s) sSubgroupFirst[s] += base;
    sListEnd = sum.y == 0u ? 0u : base.y + sum.y;
  }
  barrier();
  return sSubgroupFirst[gl_SubgroupID] + offset;
}

void main() {
  if (kSingleTriangle) {  // no interior node: a root with one leaf and one empty child
    if (bvhBuildItem() != 0u) return;
    BvhBuildNode leaf = readNode(0u);  // leaf 0: there is no interior node
    gInfo.leafCounter = 1u;
    BvhNode root;
    root.aMin = leaf.lo;
    root.aMax = leaf.hi;
    root.a = leafRef(leaf, 0u);
    root.bMin = vec3(1e30);
    root.bMax = vec3(-1e30);
    root.b = kBvhEmptyChild;
    root._pad0 = 0u;
    root._pad1 = 0u;
    if ((kForms & kEmitExactNodes) != 0u) storeNode(0u, root);
    if ((kForms & kEmitQuantizedNodes) != 0u) storeTraversalNode(0u, bvhQuantizeNode(root));
    return;
  }
  uint depth = gPush.param;
  LevelList level = gLevels[depth];
  uint k = bvhBuildItem();
  bool inLevel = k < level.count;
  uint u = gLevelNodes[level.offset + min(k, level.count - 1u)];
  BuildLinks links = readLinks(u);
  BvhBuildNode l = readNode(links.left), r = readNode(links.right);
  bool nodeA = inLevel && !becomesLeaf(links.left, l);
  bool nodeB = inLevel && !becomesLeaf(links.right, r);
  uint leavesA = inLevel && !nodeA ? l.triangleCount : 0u;
  uint leavesB = inLevel && !nodeB ? r.triangleCount : 0u;
  // A tree deeper than kBvhMaxDepth is rebuilt without restructuring (gpu_builder.cpp), so the
  // depths past the last need no list.
  bool listed = depth + 1u < kEmitMaxLevels;
  uint next = min(depth + 1u, kEmitMaxLevels - 1u);
  uvec2 at = allocate(uvec2(leavesA + leavesB, listed ? uint(nodeA) + uint(nodeB) : 0u), next);
  if (listed) {
    if (k == 0u) gLevels[next].offset = level.offset + level.count;
    if (gl_LocalInvocationIndex == 0u && sListEnd != 0u) {  // rows of kMaxGroupsX (bvhBuildItem)
      uint groups = (sListEnd + kWorkgroupSize - 1u) / kWorkgroupSize;
      atomicMax(gArgs[next].x, min(groups, kMaxGroupsX));
      atomicMax(gArgs[next].y, (groups + kMaxGroupsX - 1u) / kMaxGroupsX);
    }
  }
  if (!inLevel) return;
  uint position = gPositions[u];
  uint positionA = position + 1u;
  uint positionB = positionA + (nodeA ? gSubtreeNodes[links.left] : 0u);
  uint leafBaseA = gLeafBases[u];
  uint leafBaseB = leafBaseA + l.triangleCount;
  uint nextOffset = level.offset + level.count;
  if (nodeA) {
    gPositions[links.left] = positionA;
    gLeafBases[links.left] = leafBaseA;
    if (listed) gLevelNodes[nextOffset + at.y] = links.left;
  }
  if (nodeB) {
    gPositions[links.right] = positionB;
    gLeafBases[links.right] = leafBaseB;
    if (listed) gLevelNodes[nextOffset + at.y + uint(nodeA)] = links.right;
  }
  BvhNode out_;
  out_.aMin = l.lo;
  out_.aMax = l.hi;
  out_.a = nodeA ? positionA : leafRef(l, leafBaseA);
  out_.bMin = r.lo;
  out_.bMax = r.hi;
  out_.b = nodeB ? positionB : leafRef(r, leafBaseB);
  out_._pad0 = 0u;
  out_._pad1 = 0u;
  // The form traversal does not read is written only on request (compiled out).
  if ((kForms & kEmitExactNodes) != 0u) storeNode(position, out_);
  if ((kForms & kEmitQuantizedNodes) != 0u) storeTraversalNode(position, bvhQuantizeNode(out_));
  gSlots[u] = nodeA ? bvhEmitSlot(leafBaseB, 0u) : bvhEmitSlot(leafBaseA, leavesA);
}
