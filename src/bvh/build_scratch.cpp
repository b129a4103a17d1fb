#include "bvh/build_scratch.h"

#include "bvh/build_pass.h"
#include "bvh/emit.h"
#include "bvh/ploc.h"
#include "bvh/radix_sort.h"
#include "bvh/scan.h"
#include "bvh/treelet.h"

namespace osr::bvh {

namespace bb = gpu::bvh_build;

namespace {

vk::Buffer scratch(const vk::Context& ctx, uint64_t bytes, const char* name,
                   VkBufferUsageFlags extraUsage = 0) {
  return vk::Buffer(ctx, std::max<uint64_t>(bytes, 16), vk::MemoryUse::DeviceLocal, name,
                    extraUsage);
}

}  // namespace

BuildScratch::BuildScratch(const vk::Context& ctx, uint32_t n) : capacity(n) {
  const uint32_t interiorCount = std::max<uint32_t>(n - 1, 1);
  const uint64_t nodeBytes = sizeof(bb::BvhBuildNode);
  const uint64_t histBytes = RadixSort::histogramBytes(n);
  prims = scratch(ctx, uint64_t(n) * sizeof(gpu::bvh::BvhLeafTriangle), "bvh prims",
                  BuildTexelViews::kUsage);
  info = scratch(ctx, sizeof(bb::BvhBuildInfo), "bvh build info");
  keys = scratch(ctx, 4ull * n, "bvh keys", RadixSort::kUsage);
  keysTmp = scratch(ctx, 4ull * n, "bvh keys tmp", RadixSort::kUsage);
  values = scratch(ctx, 4ull * n, "bvh values", RadixSort::kUsage);
  valuesTmp = scratch(ctx, 4ull * n, "bvh values tmp", RadixSort::kUsage);
  hist = scratch(ctx, histBytes, "bvh radix histogram");
  partials =
      scratch(ctx, ExclusiveScan::partialsBytes(uint32_t(histBytes / 4)), "bvh scan partials");
  interior = scratch(ctx, interiorCount * nodeBytes, "bvh build interior", BuildTexelViews::kUsage);
  leaves = scratch(ctx, n * nodeBytes, "bvh build leaves", BuildTexelViews::kUsage);
  // Climb counters of bvh_refit and bvh_subtree_count, then slots of the emit passes.
  counters = scratch(ctx, 4ull * interiorCount, "bvh climb counters", EmitPass::kSlotsUsage);
  // The treelet rounds' schedule, then the emit's (by depth).
  schedule = scratch(ctx, std::max(TreeletPass::scheduleBytes(), EmitPass::scheduleBytes()),
                     "bvh level schedule");
  // Node lists of the treelet rounds, then of the emit's depths.
  nodeList = scratch(ctx, 4ull * interiorCount, "bvh node list");
  for (const vk::Buffer* b : {&prims, &info, &keys, &keysTmp, &values, &valuesTmp, &hist, &partials,
                              &interior, &leaves, &counters, &schedule, &nodeList})
    bytes += b->size();
  keyTexels = vk::BufferView::uintWords(ctx, keys, "bvh key texels");
  valueTexels = vk::BufferView::uintWords(ctx, values, "bvh value texels");
  keyTmpTexels = vk::BufferView::uintWords(ctx, keysTmp, "bvh key tmp texels");
  valueTmpTexels = vk::BufferView::uintWords(ctx, valuesTmp, "bvh value tmp texels");
  interiorTexels = vk::BufferView::uintTexels(ctx, interior, "bvh interior texels");
  leafTexels = vk::BufferView::uintTexels(ctx, leaves, "bvh leaf texels");
  primTexels = vk::BufferView::uintTexels(ctx, prims, "bvh prim texels");
  slotTexels = vk::BufferView::uintWords(ctx, counters, "bvh emit slot texels");
}

PlocScratch::PlocScratch(const vk::Context& ctx, uint32_t n) : capacity(n) {
  for (int k = 0; k < 2; ++k) {
    clusters[k] = scratch(ctx, 32ull * n, "bvh ploc clusters", PlocPass::kClusterUsage);
    clusterTexels[k] = vk::BufferView::uintTexels(ctx, clusters[k], "bvh ploc cluster texels");
  }
  nearest = scratch(ctx, 4ull * n, "bvh ploc nearest", PlocPass::kClusterUsage);
  nearestTexels = vk::BufferView::uintWords(ctx, nearest, "bvh ploc nearest texels");
  partials = scratch(ctx, 8ull * (n + bb::kWorkgroupSize), "bvh ploc partials");
  pairs = scratch(ctx, 16ull * (n / 2 + 1), "bvh ploc pairs");
  state = scratch(ctx, sizeof(bb::PlocState), "bvh ploc state", PlocPass::kStateUsage);
  tail = scratch(ctx, 64ull * tailCapacity(n), "bvh ploc tail clusters");
  for (const vk::Buffer* b :
       {&clusters[0], &clusters[1], &nearest, &partials, &pairs, &state, &tail})
    bytes += b->size();
}

}  // namespace osr::bvh
