// Host-side inspection of a tree in the device layout: SAH cost, depth and the structural
// invariants the tests and benchmarks check on every builder's output.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/cpu_builder.h"
#include "shaders/shared/bvh.h"
#include "shaders/shared/scene.h"

namespace osr::bvh {

// SAH under kSahNodeCost / kSahTriangleCost (see shaders/shared/bvh.h), normalised by the root
// area. Walks from the root, so unreachable nodes do not count.
double sahCost(const HostBvh& tree);
// Nodes on the longest root-to-leaf path (the root alone is 1).
uint32_t depth(const HostBvh& tree);
// "" when: every reference is in range, every triangle sits in exactly one reachable leaf, each
// child box contains its subtree's boxes and its triangles' vertices, no node is reached twice,
// depth <= kBvhMaxDepth. Otherwise the first violation found, in words.
std::string checkInvariants(const HostBvh& tree, std::span<const gpu::scene::Vertex> vertices,
                            std::span<const gpu::scene::Triangle> triangles);
// Reads a device tree back (nodes and the triangle indices of its leaf entries).
HostBvh download(const Bvh& bvh);

}  // namespace osr::bvh
