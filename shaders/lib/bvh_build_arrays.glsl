// The build's large arrays (BuildArrays in shared/bvh_build.h), their accessors, and the push
// block every build pass that uses them declares. Specialization constant kBuildSpecByAddress
// picks where they live: storage bindings at slots kBuildBinding* (every array within
// maxStorageBufferRange), or device addresses in the push block (any array past it). The
// compiler drops the other path, so a scene that fits bindings runs the binding code only: on
// lavapipe (Mesa 22.3) an address load costs about twice a storage-buffer load.
#ifndef OSR_BVH_BUILD_ARRAYS_GLSL
#define OSR_BVH_BUILD_ARRAYS_GLSL
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "shared/bvh_build.h"
#include "shared/scene.h"

layout(push_constant) uniform PushBlock { BuildPush gPush; };
layout(constant_id = kBuildSpecByAddress) const bool kBuildByAddress = false;

// coherent: in bvh_refit and bvh_treelet a node written by one invocation is read by the one
// that arrives second at the parent (after an atomic on the parent's counter), possibly in
// another workgroup.
layout(std430, binding = kBuildBindingTriangles) readonly buffer BuildTriangles { Triangle gTriangles[]; };
layout(std430, binding = kBuildBindingVertices) readonly buffer BuildVertices { Vertex gVertices[]; };
layout(std430, binding = kBuildBindingPrims) buffer BuildPrims { BvhLeafTriangle gPrims[]; };
layout(std430, binding = kBuildBindingInterior) coherent buffer BuildInterior { BvhBuildNode gInterior[]; };
layout(std430, binding = kBuildBindingLeaves) coherent buffer BuildLeaves { BvhBuildNode gLeaves[]; };
layout(std430, binding = kBuildBindingNodes) writeonly buffer BuildNodes { BvhNode gNodes[]; };
layout(std430, binding = kBuildBindingLeafTriangles) writeonly buffer BuildLeafTriangles {
  BvhLeafTriangle gLeafTriangles[];
};
layout(std430, binding = kBuildBindingTraversalNodes) writeonly buffer BuildTraversalNodes {
  BvhTraversalNode gTraversalNodes[];
};

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer TriangleRef { Triangle v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer VertexRef { Vertex v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer LeafTriangleRef { BvhLeafTriangle v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) coherent buffer BuildNodeRef { BvhBuildNode v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer NodeRef { BvhNode v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer TraversalNodeRef { BvhTraversalNode v[]; };

// if/else rather than ?: throughout: glslang types a ?: over two blocks' structs inconsistently.
Triangle loadTriangle(uint i) {
  if (kBuildByAddress) return TriangleRef(gPush.arrays.triangles).v[i];
  return gTriangles[i];
}
vec3 loadPosition(uint v) {
  if (kBuildByAddress) return VertexRef(gPush.arrays.vertices).v[v].position;
  return gVertices[v].position;
}
BvhLeafTriangle loadPrim(uint i) {
  if (kBuildByAddress) return LeafTriangleRef(gPush.arrays.prims).v[i];
  return gPrims[i];
}
void storePrim(uint i, BvhLeafTriangle p) {
  if (kBuildByAddress) LeafTriangleRef(gPush.arrays.prims).v[i] = p;
  else gPrims[i] = p;
}

// Build nodes: one index space, interior [0, interiorCount()), then the leaves.
uint interiorCount() { return gPush.triangleCount - 1u; }
BvhBuildNode loadInterior(uint i) {
  if (kBuildByAddress) return BuildNodeRef(gPush.arrays.interior).v[i];
  return gInterior[i];
}
void storeInterior(uint i, BvhBuildNode n) {
  if (kBuildByAddress) BuildNodeRef(gPush.arrays.interior).v[i] = n;
  else gInterior[i] = n;
}
// The fields a refit reads and writes (bounds, cost, triangle count, flags; the links stay), for
// passes that keep a node's links elsewhere: fewer words moved, and on lavapipe each moved field
// is a loop over the SIMD lanes. One macro for both the by-address and the binding form (GLSL
// has no references to buffer elements).
#define OSR_COPY_NODE_SUMS(to, from) \
  to.lo = from.lo;                   \
  to.cost = from.cost;               \
  to.hi = from.hi;                   \
  to.triangleCount = from.triangleCount; \
  to.flags = from.flags
BvhBuildNode loadInteriorSums(uint i) {
  BvhBuildNode n;
  if (kBuildByAddress) {
    OSR_COPY_NODE_SUMS(n, BuildNodeRef(gPush.arrays.interior).v[i]);
  } else {
    OSR_COPY_NODE_SUMS(n, gInterior[i]);
  }
  n.left = n.right = n.parent = kInvalidNode;
  return n;
}
void storeInteriorSums(uint i, BvhBuildNode n) {
  if (kBuildByAddress) {
    OSR_COPY_NODE_SUMS(BuildNodeRef(gPush.arrays.interior).v[i], n);
  } else {
    OSR_COPY_NODE_SUMS(gInterior[i], n);
  }
}
BvhBuildNode loadNode(uint u) {
  if (u < interiorCount()) return loadInterior(u);
  if (kBuildByAddress) return BuildNodeRef(gPush.arrays.leaves).v[u - interiorCount()];
  return gLeaves[u - interiorCount()];
}
// Single fields, where another invocation may write the node's other fields meanwhile (or a
// whole-node load would move twelve words for one).
void setParent(uint u, uint parent) {
  if (u < interiorCount()) {
    if (kBuildByAddress) BuildNodeRef(gPush.arrays.interior).v[u].parent = parent;
    else gInterior[u].parent = parent;
  } else {
    if (kBuildByAddress) BuildNodeRef(gPush.arrays.leaves).v[u - interiorCount()].parent = parent;
    else gLeaves[u - interiorCount()].parent = parent;
  }
}
// Leaf i's scene triangle (BvhBuildNode.left of a leaf).
uint leafTriangle(uint i) {
  if (kBuildByAddress) return BuildNodeRef(gPush.arrays.leaves).v[i].left;
  return gLeaves[i].left;
}
void setChildren(uint i, uint left, uint right) {
  if (kBuildByAddress) {
    BuildNodeRef(gPush.arrays.interior).v[i].left = left;
    BuildNodeRef(gPush.arrays.interior).v[i].right = right;
  } else {
    gInterior[i].left = left;
    gInterior[i].right = right;
  }
}
// The build node of a leaf over triangle `tri` (vertex copy p): its box, SAH cost and count;
// parent kInvalidNode until its parent is made.
BvhBuildNode sortedLeafNode(BvhLeafTriangle p, uint tri) {
  BvhBuildNode n;
  n.lo = min(min(p.v0.xyz, p.v1.xyz), p.v2.xyz);
  n.hi = max(max(p.v0.xyz, p.v1.xyz), p.v2.xyz);
  vec3 d = n.hi - n.lo;
  n.cost = kSahTriangleCost * 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
  n.triangleCount = 1u;
  n.left = tri;
  n.right = kInvalidNode;
  n.parent = kInvalidNode;
  n.flags = 0u;
  return n;
}
// Every field of leaf i but parent, which the lbvh invocation of its parent writes.
void initLeaf(uint i, BvhBuildNode n) {
  if (kBuildByAddress) {
    BuildNodeRef leaves = BuildNodeRef(gPush.arrays.leaves);
    OSR_COPY_NODE_SUMS(leaves.v[i], n);
    leaves.v[i].left = n.left;
    leaves.v[i].right = n.right;
  } else {
    OSR_COPY_NODE_SUMS(gLeaves[i], n);
    gLeaves[i].left = n.left;
    gLeaves[i].right = n.right;
  }
}

// The traversal layout (bvh_emit's output).
void storeNode(uint i, BvhNode n) {
  if (kBuildByAddress) NodeRef(gPush.arrays.nodes).v[i] = n;
  else gNodes[i] = n;
}
void storeTraversalNode(uint i, BvhTraversalNode n) {
  if (kBuildByAddress) TraversalNodeRef(gPush.arrays.traversalNodes).v[i] = n;
  else gTraversalNodes[i] = n;
}
void storeLeafTriangle(uint i, BvhLeafTriangle t) {
  if (kBuildByAddress) LeafTriangleRef(gPush.arrays.leafTriangles).v[i] = t;
  else gLeafTriangles[i] = t;
}

#endif
