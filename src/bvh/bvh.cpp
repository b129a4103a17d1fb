#include "bvh/bvh.h"

#include <algorithm>
#include <chrono>

#include "bvh/cpu_builder.h"
#include "bvh/tree_stats.h"

namespace osr::bvh {

uint32_t maxTriangles(const vk::Context& ctx) {
  // The largest per-triangle buffer of either builder bounds the count: one BvhNode per
  // triangle (a binary tree has fewer interior nodes than triangles).
  uint64_t perBinding = ctx.caps().maxStorageBufferRange;
  uint64_t n = perBinding / sizeof(gpu::bvh::BvhNode);
  // Build passes dispatch one invocation per triangle in one dimension of 64-wide groups.
  n = std::min<uint64_t>(n, 65535ull * 64);
  return static_cast<uint32_t>(std::min<uint64_t>(n, gpu::bvh::kBvhLeafFirstMask));
}

Bvh buildOnHost(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
                uint32_t triangleCount, BuildStats* stats) {
  auto start = std::chrono::steady_clock::now();
  auto verts = vertices.downloadVector<gpu::scene::Vertex>(vertices.size() / sizeof(gpu::scene::Vertex));
  auto tris = triangles.downloadVector<gpu::scene::Triangle>(triangleCount);
  HostBvh tree = buildCpu(verts, tris);
  Bvh bvh = upload(ctx, tree, verts, tris);
  if (stats) {
    stats->totalMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    stats->passes = {{"cpu_binned_sah", stats->totalMs}};
    stats->sahCost = sahCost(tree);
    stats->depth = depth(tree);
  }
  return bvh;
}

}  // namespace osr::bvh
