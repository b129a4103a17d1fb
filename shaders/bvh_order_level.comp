#version 460
// bvh_order_level: depth-first positions of the traversal nodes, one depth per dispatch
// (param = depth; an indirect dispatch sized by the previous depth). A node at position p puts
// its child a at p + 1 and its child b at p + 1 + (a's traversal nodes), where those children
// are traversal nodes (not leaves, not collapsed), and appends them to the next depth's list.
// Appends take one atomic per workgroup (as bvh_emit_nodes allocates leaf entries).
// Inputs: subtreeNodes, the schedule's depth 0 (the root at position 0). Outputs: positions,
// the next depth's list, count and dispatch size.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "lib/bvh_build_arrays.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kOrderBindingSubtreeNodes) readonly buffer SubtreeNodes { uint gSubtreeNodes[]; };
layout(std430, binding = kOrderBindingPositions) buffer Positions { uint gPositions[]; };
layout(std430, binding = kOrderBindingSchedule) coherent buffer Schedule {
  LevelList gLevels[kOrderMaxLevels];
  DispatchArgs gArgs[kOrderMaxLevels];
};
layout(std430, binding = kOrderBindingLevelNodes) buffer LevelNodes { uint gLevelNodes[]; };
#define OSR_BUILD_TEXEL_BINDING kOrderBindingTexels
#include "lib/bvh_build_texels.glsl"

// Traversal nodes below build node u, 0 for a leaf or a collapsed subtree.
uint subtreeNodes(uint u) {
  return u < interiorCount() ? gSubtreeNodes[u] : 0u;
}

shared uint sSubgroupFirst[kWorkgroupSize];  // per subgroup: its first entry in the next list
shared uint sGroupEnd;                       // the workgroup's end in the next list
uint allocateEntries(uint depth, uint count) {
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
    uint base = sum == 0u ? 0u : atomicAdd(gLevels[depth].count, sum);
    for (uint s = 0u; s < gl_NumSubgroups; ++s) sSubgroupFirst[s] += base;
    sGroupEnd = base + sum;
  }
  barrier();
  return sSubgroupFirst[gl_SubgroupID] + offset;
}

void main() {
  uint depth = gPush.param;
  LevelList level = gLevels[depth];
  uint k = bvhBuildItem();
  bool inLevel = k < level.count;
  uint u = gLevelNodes[level.offset + min(k, level.count - 1u)];
  BuildLinks links = readLinks(u);
  uint countA = subtreeNodes(links.left);
  bool nodeA = inLevel && countA != 0u;
  bool nodeB = inLevel && subtreeNodes(links.right) != 0u;
  uint position = gPositions[u];
  if (nodeA) gPositions[links.left] = position + 1u;
  if (nodeB) gPositions[links.right] = position + 1u + countA;
  // A tree deeper than kBvhMaxDepth is rebuilt without restructuring (gpu_builder.cpp), so the
  // levels past the last stay unused.
  uint next = min(depth + 1u, kOrderMaxLevels - 1u);
  uint nextOffset = level.offset + level.count;
  uint at = allocateEntries(next, depth + 1u < kOrderMaxLevels ? uint(nodeA) + uint(nodeB) : 0u);
  if (depth + 1u < kOrderMaxLevels) {
    if (nodeA) gLevelNodes[nextOffset + at] = links.left;
    if (nodeB) gLevelNodes[nextOffset + at + uint(nodeA)] = links.right;
    if (k == 0u) gLevels[next].offset = nextOffset;
    if (gl_LocalInvocationIndex == 0u && sGroupEnd != 0u) {  // rows of kMaxGroupsX (bvhBuildItem)
      uint groups = (sGroupEnd + kWorkgroupSize - 1u) / kWorkgroupSize;
      atomicMax(gArgs[next].x, min(groups, kMaxGroupsX));
      atomicMax(gArgs[next].y, (groups + kMaxGroupsX - 1u) / kMaxGroupsX);
    }
  }
}
