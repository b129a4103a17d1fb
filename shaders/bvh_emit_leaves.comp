#version 460
// bvh_emit_leaves: copies each triangle into its leaf entry. One invocation per leaf build node
// (triangle). Its traversal leaf is its highest collapsed ancestor (at most
// kBvhMaxLeafTriangles triangles, so the climb stops below the first larger ancestor), or itself;
// its entry is that leaf's first (from the slot bvh_emit_nodes wrote at the leaf's parent) plus
// the triangles left of it in the collapsed subtree. Every invocation runs the same steps and
// stores one entry: no store under a partial lane mask, no per-lane stack.
// Inputs: build nodes, prims, slots. Output: leaf triangles.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kEmitBindingSlots) readonly buffer Slots { uint gSlots[]; };
layout(binding = kEmitBindingSlotTexels) uniform usamplerBuffer gSlotTexels;
layout(constant_id = kEmitSpecSlotTexels) const bool kSlotTexels = false;
#define OSR_BUILD_TEXEL_BINDING kEmitBindingTexels
#include "lib/bvh_build_texels.glsl"

uint readSlot(uint i) {
  if (kSlotTexels) return texelFetch(gSlotTexels, int(i)).x;
  return gSlots[i];
}

// Triangles below build node u (a leaf holds one).
uint triangleCountOf(uint u) {
  uint ic = interiorCount();
  uint count = readTriangleCount(min(u, ic - 1u));  // read on every lane, then chosen
  return u >= ic ? 1u : count;
}

void main() {
  uint j = bvhBuildItem();
  uint n = gPush.triangleCount;
  if (j >= n) return;
  uint ic = interiorCount();
  uvec2 leaf = readLeafTriangleAndParent(j);  // (triangle, parent)
  uint entry = 0u;  // n == 1: the root's one leaf, at entry 0
  if (n > 1u) {
    // Climb while the ancestors could collapse. `rank`: triangles of the current subtree left of
    // this one; at the collapsed top, the offset within its leaf.
    uint cur = ic + j, top = cur, rank = 0u, rankInTop = 0u;
    uint topParent = leaf.y;
    bool topIsB = false;
    for (uint p = leaf.y; p != kInvalidNode;) {
      BuildLinks a = readLinks(p);
      bool fromB = a.right == cur;
      if (cur == top) {
        topParent = p;
        topIsB = fromB;
      }
      if (a.triangleCount > kBvhMaxLeafTriangles) break;
      uint leftCount = triangleCountOf(a.left);
      if (fromB) rank += leftCount;
      if ((a.flags & kFlagCollapsed) != 0u) {
        top = p;
        rankInTop = rank;
      }
      cur = p;
      p = a.parent;
    }
    uint slot = readSlot(topParent);
    entry = (slot & kBvhLeafFirstMask) + (topIsB ? slot >> kEmitSlotCountShift : 0u) + rankInTop;
  }
  storeLeafTriangle(entry, readPrim(leaf.x));
}
