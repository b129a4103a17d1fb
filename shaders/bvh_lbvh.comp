#version 460
// bvh_lbvh: the binary radix tree over the sorted Morton codes (Karras 2012, "Maximizing
// Parallelism in the Construction of BVHs, Octrees, and k-d Trees", section 4). Interior node
// i finds its key range and split from the longest common prefixes; equal codes are told apart
// by their index, as in the paper. Invocation i also initialises leaf i (sorted order): box,
// triangle, cost. Inputs: sorted keys and values, prims. Outputs: interior left/right/parent,
// leaf fields. Depth is at most 30 + ceil(log2 N) + 1 interior levels: each level's split is at
// a strictly longer common prefix of the (code, index) bits.
#extension GL_GOOGLE_include_directive : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kLbvhBindingKeys) readonly buffer Keys { uint gKeys[]; };
layout(std430, binding = kLbvhBindingValues) readonly buffer Values { uint gValues[]; };
layout(binding = kLbvhBindingKeyTexels) uniform usamplerBuffer gKeyTexels;
layout(constant_id = kLbvhSpecKeyTexels) const bool kKeyTexels = true;
#define OSR_BUILD_TEXEL_BINDING kLbvhBindingTexels
#include "lib/bvh_build_texels.glsl"

uint sortedKey(int i) {
  if (kKeyTexels) return texelFetch(gKeyTexels, i).x;
  return gKeys[i];
}

// This invocation's sorted position and key (read once: every delta() compares against it).
int gI;
uint gKeyI;

// Length of the common prefix of (key, index) at sorted positions gI and j; -1 outside.
int delta(int j) {
  int n = int(gPush.triangleCount);
  if (j < 0 || j >= n) return -1;
  uint b = sortedKey(j);
  if (gKeyI != b) return 31 - findMSB(gKeyI ^ b);
  return 32 + 31 - findMSB(uint(gI ^ j));
}

void initSortedLeaf(uint i) {
  uint tri = gValues[i];
  initLeaf(i, sortedLeafNode(readPrim(tri), tri));  // readPrim scattered: through texels
}

void main() {
  uint gi = bvhBuildItem();
  uint n = gPush.triangleCount;
  if (gi >= n) return;
  initSortedLeaf(gi);
  if (gi == 0u) setParent(0u, kInvalidNode);  // the root: interior 0, or leaf 0 when n == 1
  if (gi + 1u >= n) return;  // n - 1 interior nodes
  int i = int(gi);
  gI = i;
  gKeyI = sortedKey(i);
  int d = delta(i + 1) - delta(i - 1) >= 0 ? 1 : -1;
  int dMin = delta(i - d);
  int lMax = 2;
  while (delta(i + lMax * d) > dMin) lMax *= 2;
  int l = 0;
  for (int t = lMax / 2; t >= 1; t /= 2)
    if (delta(i + (l + t) * d) > dMin) l += t;
  int j = i + l * d;
  int dNode = delta(j);
  int s = 0;
  // t = ceil(l / 2^k) by shifts: a division by a variable is a scalar idiv per lane on lavapipe.
  for (int k = 1;; ++k) {
    int t = (l + (1 << k) - 1) >> k;
    if (delta(i + (s + t) * d) > dNode) s += t;
    if (t <= 1) break;
  }
  int gamma = i + s * d + min(d, 0);
  uint leafBase = n - 1u;
  uint left = min(i, j) == gamma ? leafBase + uint(gamma) : uint(gamma);
  uint right = max(i, j) == gamma + 1 ? leafBase + uint(gamma + 1) : uint(gamma + 1);
  setChildren(gi, left, right);
  setParent(left, gi);
  setParent(right, gi);
}
