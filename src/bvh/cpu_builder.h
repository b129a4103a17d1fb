// CPU reference builder: top-down binned SAH (Wald 2007, "On fast Construction of SAH-based
// Bounding Volume Hierarchies"), the quality yardstick of the GPU build and the source of
// trees for traversal tests. Produces the device layout of shaders/shared/bvh.h directly.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "bvh/bvh.h"
#include "shaders/shared/bvh.h"
#include "shaders/shared/scene.h"

namespace osr::bvh {

// A tree in the device layout, on the host.
struct HostBvh {
  std::vector<gpu::bvh::BvhNode> nodes;      // root at 0
  std::vector<uint32_t> leafTriangles;       // scene triangle index per leaf entry
};

struct CpuBuildOptions {
  uint32_t bins = 32;                                    // per axis, all three axes tried
  uint32_t maxLeafTriangles = gpu::bvh::kBvhMaxLeafTriangles;
};

// triangles[i].v* index into vertices (caller guarantees range). Degenerate and zero-area
// triangles are kept (they may still be hit edge-on by nothing, but every triangle is placed).
HostBvh buildCpu(std::span<const gpu::scene::Vertex> vertices,
                 std::span<const gpu::scene::Triangle> triangles, const CpuBuildOptions& options = {});

// Leaf entries with their vertex copies, in the order of tree.leafTriangles.
std::vector<gpu::bvh::BvhLeafTriangle> makeLeafTriangles(
    const HostBvh& tree, std::span<const gpu::scene::Vertex> vertices,
    std::span<const gpu::scene::Triangle> triangles);

// Uploads a host tree into device buffers of the traversal layout.
Bvh upload(const vk::Context& ctx, const HostBvh& tree,
           std::span<const gpu::scene::Vertex> vertices,
           std::span<const gpu::scene::Triangle> triangles);

}  // namespace osr::bvh
