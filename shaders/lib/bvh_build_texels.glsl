// Reads of the build arrays through RGBA32UI texel views (shared/bvh_build.h, "Texel reads"),
// for passes that read them at scattered indices and only after the dispatch that wrote them.
// The includer defines OSR_BUILD_TEXEL_BINDING (its first texel slot) and includes
// lib/bvh_build_arrays.glsl first. Without kBuildSpecTexels the same functions read the arrays.
#ifndef OSR_BVH_BUILD_TEXELS_GLSL
#define OSR_BVH_BUILD_TEXELS_GLSL

layout(binding = OSR_BUILD_TEXEL_BINDING + kBuildTexelInterior) uniform usamplerBuffer gInteriorTexels;
layout(binding = OSR_BUILD_TEXEL_BINDING + kBuildTexelLeaves) uniform usamplerBuffer gLeafTexels;
layout(binding = OSR_BUILD_TEXEL_BINDING + kBuildTexelPrims) uniform usamplerBuffer gPrimTexels;
layout(constant_id = kBuildSpecTexels) const bool kBuildTexels = false;

// A BvhBuildNode's texels: (lo, cost), (hi, triangleCount), (left, right, parent, flags).
uvec4 interiorTexel(uint i, uint k) { return texelFetch(gInteriorTexels, int(i * kBuildNodeTexels + k)); }
uvec4 leafTexel(uint i, uint k) { return texelFetch(gLeafTexels, int(i * kBuildNodeTexels + k)); }
BvhBuildNode nodeFromTexels(uvec4 a, uvec4 b, uvec4 c) {
  return BvhBuildNode(uintBitsToFloat(a.xyz), uintBitsToFloat(a.w), uintBitsToFloat(b.xyz), b.w, c.x, c.y, c.z, c.w);
}

// Build node u in the one index space (lib/bvh_build_arrays.glsl loadNode).
BvhBuildNode readNode(uint u) {
  if (!kBuildTexels) return loadNode(u);
  if (u < interiorCount()) return nodeFromTexels(interiorTexel(u, 0u), interiorTexel(u, 1u), interiorTexel(u, 2u));
  uint i = u - interiorCount();
  return nodeFromTexels(leafTexel(i, 0u), leafTexel(i, 1u), leafTexel(i, 2u));
}
BvhBuildNode readInterior(uint i) {
  if (!kBuildTexels) return loadInterior(i);
  return nodeFromTexels(interiorTexel(i, 0u), interiorTexel(i, 1u), interiorTexel(i, 2u));
}

// The topology fields of interior node i, for walks that need no bounds.
struct BuildLinks {
  uint triangleCount;
  uint left;
  uint right;
  uint parent;
  uint flags;
};
BuildLinks readLinks(uint i) {
  if (!kBuildTexels) {
    BvhBuildNode n = loadInterior(i);
    return BuildLinks(n.triangleCount, n.left, n.right, n.parent, n.flags);
  }
  uvec4 c = interiorTexel(i, 2u);
  return BuildLinks(interiorTexel(i, 1u).w, c.x, c.y, c.z, c.w);
}

// Triangles below interior node i.
uint readTriangleCount(uint i) {
  if (!kBuildTexels) return loadInterior(i).triangleCount;
  return interiorTexel(i, 1u).w;
}

// Leaf i's scene triangle (lib/bvh_build_arrays.glsl leafTriangle).
uint readLeafTriangle(uint i) {
  if (!kBuildTexels) return leafTriangle(i);
  return leafTexel(i, 2u).x;
}
// Leaf i's scene triangle and parent.
uvec2 readLeafTriangleAndParent(uint i) {
  if (!kBuildTexels) {
    BvhBuildNode n = loadNode(interiorCount() + i);
    return uvec2(n.left, n.parent);
  }
  return leafTexel(i, 2u).xz;
}

BvhLeafTriangle readPrim(uint i) {
  if (!kBuildTexels) return loadPrim(i);
  int t = int(i * kBvhLeafTriangleTexels);
  return BvhLeafTriangle(uintBitsToFloat(texelFetch(gPrimTexels, t)), uintBitsToFloat(texelFetch(gPrimTexels, t + 1)),
                         uintBitsToFloat(texelFetch(gPrimTexels, t + 2)));
}

#endif
