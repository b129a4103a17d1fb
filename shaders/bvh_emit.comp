#version 460
// bvh_emit: the traversal layout (shared/bvh.h) from the build nodes. One invocation per
// interior build node; traversal node i is build node i (root 0). Nodes that are collapsed, or
// lie below a collapsed node, emit nothing (they are unreachable). Each child that is a leaf or
// a collapsed subtree becomes a leaf: its triangles (at most kBvhMaxLeafTriangles, gathered by a
// short walk) are copied into leaf entries allocated with an atomic counter (once per subgroup).
// Inputs: build nodes, prims, info.leafCounter = 0. Outputs: nodes, leaf triangles.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kEmitBindingInfo) buffer Info { BvhBuildInfo gInfo; };
#define OSR_BUILD_TEXEL_BINDING kEmitBindingTexels
#include "lib/bvh_build_texels.glsl"

bool becomesLeaf(uint u, BvhBuildNode n) {
  return u >= interiorCount() || (n.flags & kFlagCollapsed) != 0u;
}

// Child reference for build node u: an interior index, or a leaf at `slot` holding its
// triangles (slot allocated by the caller).
uint emitChild(uint u, BvhBuildNode n, uint slot) {
  if (!becomesLeaf(u, n)) return u;
  uint count = n.triangleCount;
  if (u >= interiorCount()) {
    storeLeafTriangle(slot, readPrim(n.left));
  } else {
    // Depth-first over a subtree of at most kBvhMaxLeafTriangles leaves: the stack never holds
    // more entries than the subtree has leaves.
    uint stack[kBvhMaxLeafTriangles];
    uint sp = 0u, written = 0u;
    stack[sp++] = u;
    while (sp > 0u) {
      uint v = stack[--sp];
      if (v >= interiorCount()) {
        storeLeafTriangle(slot + written++, readPrim(readLeafTriangle(v - interiorCount())));
      } else {
        BuildLinks m = readLinks(v);
        stack[sp++] = m.left;
        stack[sp++] = m.right;
      }
    }
  }
  return kBvhLeafFlag | (count << kBvhLeafCountShift) | slot;
}

// Leaf entries for `count` triangles: one atomic per subgroup instead of one per invocation
// (a single counter that every invocation hits serialises on lavapipe's two threads).
uint allocateLeafEntries(uint count) {
  uint offset = subgroupExclusiveAdd(count);
  uint total = subgroupAdd(count);
  uint base = 0u;
  if (subgroupElect()) base = atomicAdd(gInfo.leafCounter, total);
  return subgroupBroadcastFirst(base) + offset;
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
    root.a = emitChild(0u, leaf, 0u);
    root.bMin = vec3(1e30);
    root.bMax = vec3(-1e30);
    root.b = kBvhEmptyChild;
    root._pad0 = 0u;
    root._pad1 = 0u;
    storeNode(0u, root);
    return;
  }
  if (i >= n - 1u) return;
  BuildLinks node = readLinks(i);
  bool live = (node.flags & kFlagCollapsed) == 0u;
  // Only subtrees of at most kBvhMaxLeafTriangles collapse, so only such ancestors matter.
  for (uint p = node.parent; live && p != kInvalidNode;) {
    BuildLinks a = readLinks(p);
    if (a.triangleCount > kBvhMaxLeafTriangles) break;
    if ((a.flags & kFlagCollapsed) != 0u) live = false;
    p = a.parent;
  }
  // Unreachable nodes stop here: the subgroup allocation below only counts the live lanes.
  if (!live) return;
  BvhBuildNode l = readNode(node.left), r = readNode(node.right);
  uint countA = becomesLeaf(node.left, l) ? l.triangleCount : 0u;
  uint countB = becomesLeaf(node.right, r) ? r.triangleCount : 0u;
  uint slot = allocateLeafEntries(countA + countB);
  BvhNode out_;
  out_.aMin = l.lo;
  out_.aMax = l.hi;
  out_.a = emitChild(node.left, l, slot);
  out_.bMin = r.lo;
  out_.bMax = r.hi;
  out_.b = emitChild(node.right, r, slot + countA);
  out_._pad0 = 0u;
  out_._pad1 = 0u;
  storeNode(i, out_);
}
