#include "bvh/bvh.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "bvh/cpu_builder.h"
#include "bvh/tree_stats.h"

namespace osr::bvh {

namespace {
constexpr VkDeviceSize kTexelBytes = 16;  // RGBA32UI
}  // namespace

static_assert(sizeof(gpu::bvh::BvhNode) == gpu::bvh::kBvhNodeTexels * kTexelBytes);
static_assert(sizeof(gpu::bvh::BvhTraversalNode) == gpu::bvh::kBvhTraversalNodeTexels * kTexelBytes);
static_assert(sizeof(gpu::bvh::BvhLeafTriangle) == gpu::bvh::kBvhLeafTriangleTexels * kTexelBytes);

void Bvh::makeTexelViews(const vk::Context& ctx) {
  if (!hasTraversedNodes())
    throw std::logic_error(std::string("bvh: the ") + (quantized ? "quantized" : "exact") +
                " nodes traversal would read were not built (bvh::NodeForms::Both)");
  // Where a buffer is larger than a view can be, traversal reads the storage binding
  // (texelFetchCovers is false) and the view only fills its slot.
  nodeTexels = vk::BufferView::uintTexels(ctx, traversedNodes(), "bvh node texels");
  leafTexels = vk::BufferView::uintTexels(ctx, leafData, "bvh leaf texels");
  storageRange = ctx.caps().maxStorageBufferRange;
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
  auto storage = [&](const vk::Buffer& b) {
    return vk::BufferRange(b, 0, std::min<VkDeviceSize>(b.size(), storageRange / kTexelBytes * kTexelBytes));
  };
  binder.set(base + gpu::bvh::kBvhBindingNodes, storage(traversedNodes()))
      .set(base + gpu::bvh::kBvhBindingLeafTriangles, storage(leafData))
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

TriangleLimit triangleLimit(const vk::Context& ctx) {
  const vk::Capabilities& caps = ctx.caps();
  TriangleLimit best{gpu::bvh::kBvhLeafFirstMask, "the leaf index field (2^27 leaf entries)"};
  auto consider = [&](uint64_t bytes, uint64_t perTriangle, const std::string& limit) {
    uint64_t n = bytes / perTriangle;
    if (n < best.triangles) best = {uint32_t(n), limit};
  };
  auto mib = [](uint64_t bytes) { return std::to_string(bytes >> 20) + " MiB"; };
  const uint64_t node = sizeof(gpu::bvh::BvhNode);  // the largest per-triangle array
  // Every BVH array is one allocation (nodes: one per triangle, less one).
  consider(caps.maxMemoryAllocationSize, node,
           "maxMemoryAllocationSize " + mib(caps.maxMemoryAllocationSize) + " / " + std::to_string(node) + "-byte BVH nodes");
  // Traversal reads the nodes through one binding: a texel view or a storage range.
  if (texelFetchCovers(ctx))
    consider(uint64_t(caps.maxTexelBufferElements) * kTexelBytes, node,
             "maxTexelBufferElements " + std::to_string(caps.maxTexelBufferElements) + " / " +
                 std::to_string(node / kTexelBytes) + " texels per BVH node");
  else
    consider(caps.maxStorageBufferRange, node,
             "maxStorageBufferRange " + mib(caps.maxStorageBufferRange) + " / " + std::to_string(node) + "-byte BVH nodes");
  // The build's 4-byte-per-triangle arrays (keys, values, counters) are storage bindings; its
  // larger ones are read through device addresses (shared/bvh_build.h).
  consider(caps.maxStorageBufferRange, 4, "maxStorageBufferRange " + mib(caps.maxStorageBufferRange) + " / 4-byte sort keys");
  return best;
}

uint32_t maxTriangles(const vk::Context& ctx) { return triangleLimit(ctx).triangles; }

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
