#version 460
// bvh_emit_nodes: the nodes of the traversal layout (shared/bvh.h) from the build nodes, exact
// (BvhNode) and quantized (BvhTraversalNode, shared/bvh_quantize.h), and where each leaf's
// triangles go. One invocation per interior build node; build node i becomes traversal node
// positions[i] (bvh_order_level's depth-first order, root 0). Nodes that are collapsed, or lie
// below a collapsed node, have no position: they allocate and store nothing. Each child that is a leaf or a
// collapsed subtree becomes a leaf: the leaf entries of a, then b, are allocated with an atomic
// counter (once per workgroup), and bvh_emit_leaves copies the triangles there
// (bvhEmitSlot in shared/bvh_build.h: where they start, and how many are a's).
// Inputs: build nodes, positions, info.leafCounter = 0. Outputs: nodes, traversal nodes, slots.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "lib/bvh_build_arrays.glsl"
#include "shared/bvh_quantize.h"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kEmitBindingInfo) buffer Info { BvhBuildInfo gInfo; };
layout(std430, binding = kEmitBindingSlots) writeonly buffer Slots { uint gSlots[]; };
layout(std430, binding = kEmitBindingPositions) readonly buffer Positions { uint gPositions[]; };
#define OSR_BUILD_TEXEL_BINDING kEmitBindingTexels
#include "lib/bvh_build_texels.glsl"

bool becomesLeaf(uint u, BvhBuildNode n) {
  return u >= interiorCount() || (n.flags & kFlagCollapsed) != 0u;
}

// Child reference for build node u: a traversal node's position, or a leaf of its triangles at
// `slot`.
uint childRef(uint u, BvhBuildNode n, uint slot) {
  if (!becomesLeaf(u, n)) return gPositions[u];
  return kBvhLeafFlag | (n.triangleCount << kBvhLeafCountShift) | slot;
}

// Leaf entries for `count` triangles: one atomic per workgroup (a single counter that every
// subgroup hits moves its cache line between lavapipe's two threads on every atomic). Called in
// uniform control flow by the whole workgroup.
shared uint sSubgroupFirst[kWorkgroupSize];  // per subgroup: its first entry
uint allocateLeafEntries(uint count) {
  uint offset = subgroupExclusiveAdd(count);
  uint total = subgroupAdd(count);
  if (subgroupElect()) sSubgroupFirst[gl_SubgroupID] = total;
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    uint sum = 0u;
    for (uint s = 0u; s < gl_NumSubgroups; ++s) {
      uint t = sSubgroupFirst[s];
      sSubgroupFirst[s] = sum;
      sum += t;
    }
    uint base = atomicAdd(gInfo.leafCounter, sum);
    for (uint s = 0u; s < gl_NumSubgroups; ++s) sSubgroupFirst[s] += base;
  }
  barrier();
  return sSubgroupFirst[gl_SubgroupID] + offset;
}

void main() {
  uint i = bvhBuildItem();
  uint n = gPush.triangleCount;
  if (n == 1u) {  // no interior node: a root with one leaf and one empty child
    if (i != 0u) return;
    BvhBuildNode leaf = readNode(0u);  // leaf 0: there is no interior node
    gInfo.leafCounter = 1u;
    BvhNode root;
    root.aMin = leaf.lo;
    root.aMax = leaf.hi;
    root.a = childRef(0u, leaf, 0u);
    root.bMin = vec3(1e30);
    root.bMax = vec3(-1e30);
    root.b = kBvhEmptyChild;
    root._pad0 = 0u;
    root._pad1 = 0u;
    storeNode(0u, root);
    storeTraversalNode(0u, bvhQuantizeNode(root));
    return;
  }
  // Past the last node: no leaf entries, no stores, but through the allocation's barriers.
  bool inRange = i < n - 1u;
  BuildLinks node = readLinks(min(i, n - 2u));
  uint position = gPositions[min(i, n - 2u)];
  bool live = inRange && position != kInvalidNode;
  BvhBuildNode l = readNode(node.left), r = readNode(node.right);
  uint countA = live && becomesLeaf(node.left, l) ? l.triangleCount : 0u;
  uint countB = live && becomesLeaf(node.right, r) ? r.triangleCount : 0u;
  uint slot = allocateLeafEntries(countA + countB);
  if (!live) return;
  BvhNode out_;
  out_.aMin = l.lo;
  out_.aMax = l.hi;
  out_.a = childRef(node.left, l, slot);
  out_.bMin = r.lo;
  out_.bMax = r.hi;
  out_.b = childRef(node.right, r, slot + countA);
  out_._pad0 = 0u;
  out_._pad1 = 0u;
  storeNode(position, out_);
  storeTraversalNode(position, bvhQuantizeNode(out_));
  gSlots[i] = bvhEmitSlot(slot, countA);
}
