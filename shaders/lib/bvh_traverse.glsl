// Ray traversal of the BVH of shaders/shared/bvh.h: closest hit and any hit (occlusion).
//
// The including shader #defines OSR_BVH_BINDING (first of kBvhBindingCount consecutive
// bindings, see shared/bvh.h) before including this file; the pipeline sets specialization
// constant kBvhSpecTexelFetch (bvh::Bvh::spec). If OSR_BVH_ALPHA_TEST is
// defined, hits for which `bool osrAlphaCutout(uint triangle, vec2 barycentrics, vec3 rayOrigin,
// vec3 rayInvDir)` returns true (the ray: for a per-ray hash, e.g. stochastic transparency)
// are skipped (the includer provides it, normally through shaders/lib/scene.glsl).
//
// Ray-triangle test: watertight (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle
// Intersection"), so rays through shared edges and vertices never slip between triangles.
// Ray-box test: slabs with the far distance scaled up by 1 + 2*gamma(3) (Ize 2013, "Robust BVH
// Ray Traversal") so boxes that the triangle test would hit are never culled by rounding.
// Stack: one entry per level descended; the builders bound the depth by kBvhMaxDepth.
#ifndef OSR_BVH_TRAVERSE_GLSL
#define OSR_BVH_TRAVERSE_GLSL
#extension GL_KHR_shader_subgroup_vote : require
#ifdef OSR_BVH_RAY_POOL
#extension GL_KHR_shader_subgroup_ballot : require
#endif
#include "shared/bvh.h"

#ifndef OSR_BVH_BINDING
#error "define OSR_BVH_BINDING before including lib/bvh_traverse.glsl"
#endif

// The node array as 16-byte words: exact BvhNodes (kBvhNodeTexels words each) or quantized
// BvhTraversalNodes (kBvhTraversalNodeTexels), as specialization constant kBvhSpecQuantized says
// (C++: bvh::Bvh::quantized, which decides which array is bound).
layout(std430, binding = OSR_BVH_BINDING + kBvhBindingNodes) readonly buffer OsrBvhNodes {
  uvec4 gBvhNodeWords[];
};
layout(std430, binding = OSR_BVH_BINDING + kBvhBindingLeafTriangles) readonly buffer OsrBvhLeaves {
  BvhLeafTriangle gBvhLeafTriangles[];
};

layout(binding = OSR_BVH_BINDING + kBvhBindingNodeTexels) uniform usamplerBuffer gBvhNodeTexels;
layout(binding = OSR_BVH_BINDING + kBvhBindingLeafTexels) uniform usamplerBuffer gBvhLeafTexels;
layout(constant_id = kBvhSpecTexelFetch) const bool kBvhTexelFetch = true;
layout(constant_id = kBvhSpecQuantized) const bool kBvhQuantized = false;

// Texels hold raw bits (RGBA32UI, not RGBA32F): a float format could flush the denormal bit
// patterns of small triangle indices in v0.w or of child references.
uvec4 osrBvhNodeWord(uint i) {
  if (kBvhTexelFetch) return texelFetch(gBvhNodeTexels, int(i));
  return gBvhNodeWords[i];
}

BvhNode osrBvhExactNode(uint i) {
  uint base = i * kBvhNodeTexels;
  uvec4 t0 = osrBvhNodeWord(base), t1 = osrBvhNodeWord(base + 1u);
  uvec4 t2 = osrBvhNodeWord(base + 2u), t3 = osrBvhNodeWord(base + 3u);
  BvhNode n;
  n.aMin = uintBitsToFloat(t0.xyz);
  n.a = t0.w;
  n.aMax = uintBitsToFloat(t1.xyz);
  n.b = t1.w;
  n.bMin = uintBitsToFloat(t2.xyz);
  n._pad0 = 0u;
  n.bMax = uintBitsToFloat(t3.xyz);
  n._pad1 = 0u;
  return n;
}

BvhTraversalNode osrBvhQuantizedNode(uint i) {
  BvhTraversalNode n;
  n.frame = osrBvhNodeWord(i * kBvhTraversalNodeTexels);
  n.boxes = osrBvhNodeWord(i * kBvhTraversalNodeTexels + 1u);
  return n;
}

BvhLeafTriangle osrBvhLeafTriangle(uint i) {
  if (!kBvhTexelFetch) return gBvhLeafTriangles[i];
  int base = int(i * kBvhLeafTriangleTexels);
  BvhLeafTriangle t;
  t.v0 = uintBitsToFloat(texelFetch(gBvhLeafTexels, base));
  t.v1 = uintBitsToFloat(texelFetch(gBvhLeafTexels, base + 1));
  t.v2 = uintBitsToFloat(texelFetch(gBvhLeafTexels, base + 2));
  return t;
}

// triangle = index into the scene's Triangle buffer; barycentrics = weights of v1, v2.
struct Hit {
  float t;
  uint triangle;
  vec2 barycentrics;
};

#ifdef OSR_BVH_ALPHA_TEST
bool osrAlphaCutout(uint triangle, vec2 barycentrics, vec3 rayOrigin, vec3 rayInvDir);
#endif

// Per-ray constants of the watertight test and the slab test.
struct OsrBvhRay {
  vec3 origin;
  vec3 invDir;
  vec3 originScaled;  // origin * invDir, so a slab distance is one fma
  bvec3 dirNegative;  // the box's max plane is the near one on these axes
  uvec3 nearShift;    // quantized nodes: per axis, where the near plane's byte of child a sits
  uvec3 farShift;     // in the node's boxes (the max plane's where dirNegative); child b's: + 16
  ivec3 k;            // kx, ky, kz: kz the dominant axis, kx/ky keeping the winding
  vec3 shear;         // Sx, Sy, Sz
};

OsrBvhRay osrBvhMakeRay(vec3 origin, vec3 dir) {
  OsrBvhRay r;
  r.origin = origin;
  // Zero components would make 0 * inf = NaN in the slab test; a tiny same-signed value keeps
  // the box test conservative (the triangle test uses the exact direction).
  const float kTiny = 1e-30;
  vec3 safe = mix(dir, mix(vec3(kTiny), vec3(-kTiny), lessThan(dir, vec3(0.0))),
                  lessThan(abs(dir), vec3(kTiny)));
  r.invDir = 1.0 / safe;
  r.originScaled = origin * r.invDir;
  r.dirNegative = lessThan(r.invDir, vec3(0.0));
  r.nearShift = mix(uvec3(0u), uvec3(8u), r.dirNegative);
  r.farShift = mix(uvec3(8u), uvec3(0u), r.dirNegative);
  vec3 a = abs(dir);
  int kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  int kx = kz == 2 ? 0 : kz + 1;
  int ky = kx == 2 ? 0 : kx + 1;
  if (dir[kz] < 0.0) {
    int tmp = kx;
    kx = ky;
    ky = tmp;
  }
  r.k = ivec3(kx, ky, kz);
  r.shear = vec3(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
  return r;
}

const float kOsrBvhExitScale = 1.00000036;  // 1 + 2 * gamma(3)

// Larger and smaller of two floats as a compare and a select: GLSL's max and min must return
// the other operand for a NaN, which lavapipe pays with a compare and a blend besides the
// vmaxps. No NaN reaches the slab test (osrBvhMakeRay keeps 1 / dir finite).
float osrBvhMax(float a, float b) { return a > b ? a : b; }
float osrBvhMin(float a, float b) { return a < b ? a : b; }

// True when the ray overlaps a box within [tMin, tFar], given the distances of its near and far
// planes per axis; tEnter = entry distance.
bool osrBvhSlabs(vec3 near, vec3 far, float tMin, float tFar, out float tEnter) {
  tEnter = osrBvhMax(osrBvhMax(near.x, near.y), osrBvhMax(near.z, tMin));
  float tExit = osrBvhMin(osrBvhMin(far.x, far.y), osrBvhMin(far.z, tFar)) * kOsrBvhExitScale;
  return tEnter <= tExit;
}

// Tests both children of node i, and returns their references (a, b). Exact nodes: r.dirNegative
// picks each axis's near and far planes once per ray instead of a min and a max per box.
// Quantized nodes (shared/bvh.h BvhTraversalNode): a plane o + q * s is at distance
// q * (s / d) + (o / d - origin / d) along the ray, two per-node terms per axis and then one fma
// per plane; r.nearShift picks each axis's near and far byte.
uvec2 osrBvhTestChildren(OsrBvhRay r, uint i, float tMin, float tFar, out bool ha, out float ta,
                         out bool hb, out float tb) {
  if (kBvhQuantized) {
    BvhTraversalNode n = osrBvhQuantizedNode(i);
    vec3 origin = uintBitsToFloat(n.frame.xyz & ~kBvhQuantizeExponentBits);
    vec3 scale = uintBitsToFloat((n.frame.xyz & kBvhQuantizeExponentBits) << 23u);
    vec3 step = scale * r.invDir;
    vec3 base = origin * r.invDir - r.originScaled;
    uvec3 q = n.boxes.yzw;
    ha = osrBvhSlabs(vec3((q >> r.nearShift) & 0xffu) * step + base,
                     vec3((q >> r.farShift) & 0xffu) * step + base, tMin, tFar, ta);
    hb = osrBvhSlabs(vec3((q >> (r.nearShift + 16u)) & 0xffu) * step + base,
                     vec3((q >> (r.farShift + 16u)) & 0xffu) * step + base, tMin, tFar, tb);
    return uvec2(n.frame.w, n.boxes.x);
  }
  BvhNode n = osrBvhExactNode(i);
  ha = osrBvhSlabs(mix(n.aMin, n.aMax, r.dirNegative) * r.invDir - r.originScaled,
                   mix(n.aMax, n.aMin, r.dirNegative) * r.invDir - r.originScaled, tMin, tFar, ta);
  hb = osrBvhSlabs(mix(n.bMin, n.bMax, r.dirNegative) * r.invDir - r.originScaled,
                   mix(n.bMax, n.bMin, r.dirNegative) * r.invDir - r.originScaled, tMin, tFar, tb);
  return uvec2(n.a, n.b);
}

// Watertight test; on a hit inside (tMin, tFar) returns t and the weights of v1, v2.
bool osrBvhTriangle(OsrBvhRay r, vec3 v0, vec3 v1, vec3 v2, float tMin, float tFar,
                    out float t, out vec2 bary) {
  vec3 A = v0 - r.origin;
  vec3 B = v1 - r.origin;
  vec3 C = v2 - r.origin;
  int kx = r.k.x, ky = r.k.y, kz = r.k.z;
  float ax = A[kx] - r.shear.x * A[kz];
  float ay = A[ky] - r.shear.y * A[kz];
  float bx = B[kx] - r.shear.x * B[kz];
  float by = B[ky] - r.shear.y * B[kz];
  float cx = C[kx] - r.shear.x * C[kz];
  float cy = C[ky] - r.shear.y * C[kz];
  // precise: unfused, so a shared edge gives exactly opposite values in its two triangles.
  precise float U = cx * by - cy * bx;
  precise float V = ax * cy - ay * cx;
  precise float W = bx * ay - by * ax;
  t = 0.0;
  bary = vec2(0.0);
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  float det = U + V + W;
  if (det == 0.0) return false;
  float T = U * (r.shear.z * A[kz]) + V * (r.shear.z * B[kz]) + W * (r.shear.z * C[kz]);
  float rcpDet = 1.0 / det;
  t = T * rcpDet;
  if (!(t > tMin && t < tFar)) return false;
  bary = vec2(V, W) * rcpDet;
  return true;
}

// The loop of both queries and of the ray pool; `anyHit` is a constant at each call site, so
// the compiler specialises it away.
//
// Leaves are intersected in a separate phase, for the whole SIMD group at once (Aila & Laine
// 2009, "Understanding the Efficiency of Ray Traversal on GPUs": while-while with speculative
// traversal). The walk goes on while any lane of the subgroup still looks for its first leaf;
// a lane that found one keeps walking until it holds a second. Then every lane tests all the
// triangles it holds in one loop. lavapipe runs a loop body for all 8 lanes while any lane
// needs it, so intersecting leaves where the walk meets them cost max over lanes of each
// node's leaf triangles at every node, several times the lanes' mean work on incoherent rays;
// gathering them first costs one max per phase.
//
// With OSR_BVH_RAY_POOL defined the loop is osrBvhTracePool instead: a lane whose ray is done
// takes the next ray of the subgroup's pool after each leaf phase (Aila & Laine's dynamic ray
// fetch), so a subgroup no longer runs as long as its slowest ray while the other lanes idle.
// The includer provides
//   OsrBvhPoolRayDesc osrBvhPoolRay(uint i);          // ray i of the pool
//   void osrBvhPoolResult(uint i, bool found, Hit hit); // its result
// bvhClosestHit and bvhAnyHit stay defined. Both loops are the text of
// lib/bvh_traverse_loop.glsl. (A more general pool, whose includer made each lane's next ray
// and took its result in one hook called when half the lanes were idle, was slower, also in
// osr_direct, the one kernel that tried it: docs/bvh.md.)
#ifdef OSR_BVH_RAY_POOL
struct OsrBvhPoolRayDesc {
  vec3 origin;
  float tMin;
  vec3 dir;
  float tMax;
};
OsrBvhPoolRayDesc osrBvhPoolRay(uint i);
void osrBvhPoolResult(uint i, bool found, Hit hit);
#endif

#define OSR_BVH_LOOP_POOL 0
#include "lib/bvh_traverse_loop.glsl"
#ifdef OSR_BVH_RAY_POOL
#undef OSR_BVH_LOOP_POOL
#define OSR_BVH_LOOP_POOL 1
#include "lib/bvh_traverse_loop.glsl"
#endif
#undef OSR_BVH_LOOP_POOL

bool bvhClosestHit(vec3 origin, vec3 dir, float tMin, float tMax, out Hit hit) {
  return osrBvhTraverse(origin, dir, tMin, tMax, false, hit);
}

bool bvhAnyHit(vec3 origin, vec3 dir, float tMin, float tMax) {
  Hit unused;
  return osrBvhTraverse(origin, dir, tMin, tMax, true, unused);
}

#endif
