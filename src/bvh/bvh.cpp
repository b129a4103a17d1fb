#include "bvh/bvh.h"

#include <algorithm>
#include <chrono>

#include "bvh/cpu_builder.h"
#include "bvh/tree_stats.h"

namespace osr::bvh {

namespace {
constexpr VkDeviceSize kTexelBytes = 16;  // RGBA32UI
}  // namespace

static_assert(sizeof(gpu::bvh::BvhNode) == gpu::bvh::kBvhNodeTexels * kTexelBytes);
static_assert(sizeof(gpu::bvh::BvhLeafTriangle) == gpu::bvh::kBvhLeafTriangleTexels * kTexelBytes);

void Bvh::makeTexelViews(const vk::Context& ctx) {
  // Where a buffer is larger than a view can be, traversal reads the storage binding
  // (texelFetchCovers is false) and the view only fills its slot.
  nodeTexels = vk::BufferView::uintTexels(ctx, nodes, "bvh node texels");
  leafTexels = vk::BufferView::uintTexels(ctx, leafData, "bvh leaf texels");
}

std::array<VkDescriptorType, gpu::bvh::kBvhBindingCount> Bvh::descriptorTypes() {
  std::array<VkDescriptorType, gpu::bvh::kBvhBindingCount> t;
  t[gpu::bvh::kBvhBindingNodes] = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  t[gpu::bvh::kBvhBindingLeafTriangles] = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  t[gpu::bvh::kBvhBindingNodeTexels] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  t[gpu::bvh::kBvhBindingLeafTexels] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}

void Bvh::bind(vk::Binder& binder, uint32_t base) const {
  binder.set(base + gpu::bvh::kBvhBindingNodes, nodes)
      .set(base + gpu::bvh::kBvhBindingLeafTriangles, leafData)
      .setTexel(base + gpu::bvh::kBvhBindingNodeTexels, nodeTexels.handle())
      .setTexel(base + gpu::bvh::kBvhBindingLeafTexels, leafTexels.handle());
}

bool texelFetchCovers(const vk::Context& ctx) {
  return ctx.caps().maxStorageBufferRange / kTexelBytes <= ctx.caps().maxTexelBufferElements;
}

vk::SpecConstant traversalSpec(const vk::Context& ctx, Access access) {
  bool texel = access == Access::TexelFetch || (access == Access::Auto && texelFetchCovers(ctx));
  return vk::specUint(gpu::bvh::kBvhSpecTexelFetch, texel ? 1u : 0u);
}

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
