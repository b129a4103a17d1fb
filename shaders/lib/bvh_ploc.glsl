// The PLOC passes' bindings and helpers (shared/bvh_build.h, "PLOC"). The includer has included
// lib/bvh_build_arrays.glsl.
#ifndef OSR_BVH_PLOC_GLSL
#define OSR_BVH_PLOC_GLSL
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "lib/bvh_build_refit.glsl"

layout(binding = kPlocBindingClusterTexels) uniform usamplerBuffer gClusterTexels;
layout(std430, binding = kPlocBindingNextClusters) writeonly buffer NextClusters { uvec4 gNextClusters[]; };
layout(binding = kPlocBindingClusterNodeTexels) uniform usamplerBuffer gClusterNodeTexels;
layout(std430, binding = kPlocBindingNextClusterNodes) writeonly buffer NextClusterNodes { uint gNextClusterNodes[]; };
layout(std430, binding = kPlocBindingNearest) buffer Nearest { uint gNearest[]; };
layout(binding = kPlocBindingNearestTexels) uniform usamplerBuffer gNearestTexels;
layout(std430, binding = kPlocBindingPartials) buffer Partials { uint gPartials[]; };
layout(std430, binding = kPlocBindingState) buffer State { PlocState gState; };
layout(std430, binding = kPlocBindingSubtreeNodes) buffer SubtreeNodes { uint gSubtreeNodes[]; };
layout(std430, binding = kPlocBindingFirstLeaf) buffer FirstLeaf { uint gFirstLeaf[]; };
layout(binding = kPlocBindingSubtreeNodeTexels) uniform usamplerBuffer gSubtreeNodeTexels;
layout(binding = kPlocBindingFirstLeafTexels) uniform usamplerBuffer gFirstLeafTexels;
// A mutual pair: (lower cluster's node, upper cluster's node, the parent's index, its first leaf).
layout(std430, binding = kPlocBindingPairs) buffer Pairs { uvec4 gPairs[]; };

// Where the per-subgroup pair counts start in partials.
uint plocPairPartials() { return gPush.triangleCount + kWorkgroupSize; }

// Clusters at the start of this iteration (push param: its parity).
uint plocClusterCount() { return gState.count[gPush.param]; }

// A cluster: its box, quantized to 21 bits per plane in the frame of state.frame (lo rounded
// down, hi up; packed in one texel of the cluster array), and its build node (the node array).
struct PlocCluster {
  uvec3 lo;
  uvec3 hi;
  uint node;
};

PlocCluster plocQuantize(vec3 lo, vec3 hi, vec4 frame, uint node) {
  const float kTop = float(kPlocQuantizeMax);
  uvec3 l = uvec3(clamp(floor((lo - frame.xyz) * frame.w), 0.0, kTop));  // NaN: 0
  uvec3 h = uvec3(clamp(ceil((hi - frame.xyz) * frame.w), 0.0, kTop));
  return PlocCluster(l, h, node);
}

// Cluster i's box (through the texel view: a gather on lavapipe; the neighbours a lane reads
// lie next to each other in memory): 6 x 21 bits, lo.xyz then hi.xyz, from the low bits up.
PlocCluster plocClusterBox(uint i) {
  uvec4 w = texelFetch(gClusterTexels, int(i));
  const uint m = kPlocQuantizeMax;
  uvec3 lo = uvec3(w.x & m, (w.x >> 21u) | ((w.y & 0x3ffu) << 11u), (w.y >> 10u) & m);
  uvec3 hi = uvec3((w.y >> 31u) | ((w.z & 0xfffffu) << 1u), (w.z >> 20u) | ((w.w & 0x1ffu) << 12u), (w.w >> 9u) & m);
  return PlocCluster(lo, hi, 0u);
}
PlocCluster plocCluster(uint i) {
  PlocCluster c = plocClusterBox(i);
  c.node = texelFetch(gClusterNodeTexels, int(i)).x;
  return c;
}
void plocStoreCluster(uint i, PlocCluster c) {
  gNextClusters[i] = uvec4(c.lo.x | (c.lo.y << 21u), (c.lo.y >> 11u) | (c.lo.z << 10u) | (c.hi.x << 31u),
                           (c.hi.x >> 1u) | (c.hi.y << 20u), (c.hi.y >> 12u) | (c.hi.z << 9u));
  gNextClusterNodes[i] = c.node;
}

// The cluster of the union of two clusters' boxes, holding `node`.
PlocCluster plocUnion(PlocCluster a, PlocCluster b, uint node) {
  return PlocCluster(min(a.lo, b.lo), max(a.hi, b.hi), node);
}

// Half the surface area of the union of two clusters' boxes, in frame units.
float plocUnionArea(PlocCluster a, PlocCluster b) {
  vec3 d = vec3(max(a.hi, b.hi) - min(a.lo, b.lo));
  return d.x * d.y + d.y * d.z + d.z * d.x;
}

// Cluster i's nearest neighbour (bvh_ploc_nearest's, read by later dispatches: a gather).
uint plocNearest(uint i) { return texelFetch(gNearestTexels, int(i)).x; }

// Whether cluster i survives this iteration's merge (it is in range, and has no mutual nearest
// neighbour or is the lower of a mutual pair), and whether it merges (the lower of a pair, with
// cluster `partner`). Every lane reads: lanes past count read the last cluster's.
bool plocSurvives(uint i, uint count, out bool merges, out uint partner) {
  uint j = plocNearest(min(i, count - 1u));
  bool mutual = i < count && plocNearest(j) == i;
  merges = mutual && i < j;
  partner = j;
  return i < count && (!mutual || i < j);
}

// This subgroup's place among the dispatch's subgroups, which bvh_ploc_count's survivor counts
// and bvh_ploc_compact's offsets are kept by (per subgroup: no barrier, no shared memory, which
// lavapipe runs slowly). Assumes, as lavapipe and the GPUs we know lay them out, that a
// subgroup's lanes are consecutive invocations; the dispatch is one row (bvh_ploc_plan).
uint plocSubgroupIndex() {
  return (gl_WorkGroupID.x * kWorkgroupSize) / gl_SubgroupSize + gl_SubgroupID;
}

// What a merge needs of a cluster's build node beyond its BvhBuildNode: its traversal nodes
// (0 for a leaf) and first leaf.
uint plocSubtreeNodes(uint node) {
  uint ic = interiorCount();
  uint count = texelFetch(gSubtreeNodeTexels, int(min(node, ic - 1u))).x;  // read by every lane
  return node < ic ? count : 0u;
}
uint plocFirstLeaf(uint node) {
  uint ic = interiorCount();
  uint first = texelFetch(gFirstLeafTexels, int(min(node, ic - 1u))).x;
  return node < ic ? first : node - ic;
}

#endif
