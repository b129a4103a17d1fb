// The build's large arrays through their device addresses (BuildArrays in shared/bvh_build.h,
// which says why they are not bindings), and the push block every build pass declares. Each
// array reads as `gName[i]`, like the storage-buffer arrays they replace.
#ifndef OSR_BVH_BUILD_ARRAYS_GLSL
#define OSR_BVH_BUILD_ARRAYS_GLSL
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "shared/bvh_build.h"
#include "shared/scene.h"

layout(push_constant) uniform PushBlock { BuildPush gPush; };

// coherent: in bvh_refit and bvh_treelet a node written by one invocation is read by the one
// that arrives second at the parent (after an atomic on the parent's counter), possibly in
// another workgroup.
layout(buffer_reference, std430, buffer_reference_align = 16) coherent buffer BvhBuildNodeArray {
  BvhBuildNode v[];
};
layout(buffer_reference, std430, buffer_reference_align = 16) buffer BvhLeafTriangleArray {
  BvhLeafTriangle v[];
};
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer BvhNodeArray {
  BvhNode v[];
};
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SceneTriangleArray {
  Triangle v[];
};
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SceneVertexArray {
  Vertex v[];
};

#define gTriangles SceneTriangleArray(gPush.arrays.triangles).v
#define gVertices SceneVertexArray(gPush.arrays.vertices).v
#define gPrims BvhLeafTriangleArray(gPush.arrays.prims).v
#define gInterior BvhBuildNodeArray(gPush.arrays.interior).v
#define gLeaves BvhBuildNodeArray(gPush.arrays.leaves).v
#define gNodes BvhNodeArray(gPush.arrays.nodes).v
#define gLeafTriangles BvhLeafTriangleArray(gPush.arrays.leafTriangles).v

#endif
