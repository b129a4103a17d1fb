// The BVH as traversal sees it (std430), written by the GPU build (src/bvh/gpu_builder.cpp) and
// by the CPU reference builder's upload (src/bvh/cpu_builder.cpp), read by
// shaders/lib/bvh_traverse.glsl.
//
// A binary tree whose nodes store the bounds of both children (one node fetch decides which
// children a ray enters), in depth-first order (child a follows its parent, b follows a's
// subtree), each node twice: exact (BvhNode) and quantized (BvhTraversalNode); traversal reads
// one of the two (kBvhSpecQuantized). Node 0 is the root. A child reference is either the index of another
// node or, with kBvhLeafFlag set, a leaf: `count` consecutive BvhLeafTriangle entries starting at
// `first`. A leaf of count 0 is an empty child (its box is inverted so no ray enters it). When
// both children are non-empty leaves, b's entries follow a's, so the leaves a ray enters at a node
// are one range (traversal relies on it; bvh::checkInvariants checks it).
// Leaves hold a reordered copy of the triangles' world-space vertices, so traversal reads no
// scene buffer; the original triangle index rides in v0.w.
#ifndef OSR_SHARED_BVH_H
#define OSR_SHARED_BVH_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(bvh)

// Bindings a traversing shader declares, from OSR_BVH_BINDING on: nodes and leaf triangles as
// storage buffers, then the same two buffers as RGBA32UI uniform texel buffers. Traversal reads
// one pair, chosen by specialization constant kBvhSpecTexelFetch (C++: bvh::Bvh::spec): on
// lavapipe a texel fetch at a per-lane index is a straight-line gather while a storage-buffer
// load is a loop over the SIMD lanes; devices whose maxTexelBufferElements cannot cover a
// maxStorageBufferRange-sized buffer read the storage buffers. All four are always bound.
OSR_CONST(uint, kBvhBindingCount, 4u);
OSR_CONST(uint, kBvhBindingNodes, 0u);
OSR_CONST(uint, kBvhBindingLeafTriangles, 1u);
OSR_CONST(uint, kBvhBindingNodeTexels, 2u);
OSR_CONST(uint, kBvhBindingLeafTexels, 3u);
OSR_CONST(uint, kBvhSpecTexelFetch, 200u);  // constant_id; ids below 200 belong to the passes
// constant_id: traversal reads quantized BvhTraversalNodes, not exact BvhNodes (C++:
// bvh::quantizedTraversal decides by the triangle count, bvh::Bvh::quantized records it).
OSR_CONST(uint, kBvhSpecQuantized, 202u);
OSR_CONST(uint, kBvhNodeTexels, 4u);        // 16-byte texels per BvhNode
OSR_CONST(uint, kBvhLeafTriangleTexels, 3u);

// Traversal keeps one stack entry per level it descends (the far child), so a tree whose
// longest root-to-leaf path has at most kBvhMaxDepth nodes never overflows the stack. Both
// builders guarantee that bound (see cpu_builder.cpp and gpu_builder.cpp).
OSR_CONST(uint, kBvhMaxDepth, 64u);

OSR_CONST(uint, kBvhLeafFlag, 0x80000000u);
OSR_CONST(uint, kBvhLeafCountShift, 27u);
OSR_CONST(uint, kBvhLeafCountMask, 15u);
OSR_CONST(uint, kBvhLeafFirstMask, 0x07ffffffu);  // 128 Mi leaf entries
OSR_CONST(uint, kBvhMaxLeafTriangles, 8u);
OSR_CONST(uint, kBvhEmptyChild, 0x80000000u);     // leaf flag, count 0

// Surface-area-heuristic cost constants shared by the CPU builder's split decisions, the GPU
// build's quality step and every reported SAH figure:
//   SAH = (sum over interior nodes of kSahNodeCost * area(node)
//          + sum over leaves of kSahTriangleCost * area(leaf) * triangles(leaf)) / area(root)
// (Karras & Aila 2013 use the same 1.2 : 1 ratio.)
OSR_CONST(float, kSahNodeCost, 1.2);
OSR_CONST(float, kSahTriangleCost, 1.0);

struct BvhNode {
  vec3 aMin;
  uint a;  // child reference (node index or leaf)
  vec3 aMax;
  uint b;
  vec3 bMin;
  uint _pad0;
  vec3 bMax;
  uint _pad1;
};

// Traversal's copy of a BvhNode in 32 bytes (two texels, half a BvhNode): both child boxes
// quantized to 8 bits per plane within the node's box (Ylitie, Karras, Laine 2017, "Efficient
// Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs"). Per axis the node keeps an
// origin o, a float whose low 8 mantissa bits are zero (they hold the axis's scale exponent
// instead), and a scale s = 2^(e - 127); a quantized plane q stands for o + q * s. Quantization is
// conservative: o + qLo * s <= the child's min, o + qHi * s >= its max, so a ray that enters the
// exact box enters the quantized one. An empty child is qLo = 255 > qHi = 0 on every axis.
// Incoherent traversal on lavapipe waits on node fetches, and this halves their bytes.
// Written by bvh::quantizeNode (src/bvh/node_quantize.h) and its GLSL twin in bvh_emit_nodes.
struct BvhTraversalNode {
  uvec4 frame;  // xyz: origin bits | scale exponent (low byte); w: child reference a
  uvec4 boxes;  // x: child reference b; y, z, w: axis x, y, z bytes aLo | aHi << 8 | bLo << 16 | bHi << 24
};
OSR_CONST(uint, kBvhTraversalNodeTexels, 2u);
OSR_CONST(uint, kBvhQuantizeExponentBits, 0xffu);  // the low byte of each origin

// One triangle of a leaf: world-space vertices; v0.w holds the scene triangle index (as bits).
struct BvhLeafTriangle {
  vec4 v0;
  vec4 v1;
  vec4 v2;
};

OSR_NAMESPACE_END
#endif
