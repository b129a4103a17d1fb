#include "bvh/build_passes.h"

#include <algorithm>
#include <optional>
#include <string>

#include "common/error.h"
#include "vk/binder.h"
#include "vk/timer.h"

namespace osr::bvh {

namespace bb = gpu::bvh_build;
using bb::BuildPush;

namespace {
// See climbFence() in shaders/lib/bvh_build_nodes.glsl for why CPU devices run without fences.
std::vector<vk::SpecConstant> climbSpec(const vk::Context& ctx, uint32_t treeletLeaves) {
  std::vector<vk::SpecConstant> spec = {vk::specUint(bb::kClimbSpecFences, ctx.caps().isCpu() ? 0u : 1u)};
  if (treeletLeaves) spec.push_back(vk::specUint(bb::kTreeletSpecLeaves, treeletLeaves));
  return spec;
}
uint32_t groups(uint64_t items) { return vk::groupCount(std::max<uint64_t>(items, 1), bb::kWorkgroupSize); }
}  // namespace

BoundsPass::BoundsPass(const vk::Context& ctx)
    : ctx_(ctx), pipeline_(ctx, shaders::Id::bvh_bounds, bb::kBoundsBindingCount, sizeof(BuildPush)) {}

void BoundsPass::record(VkCommandBuffer cmd, const Args& a) const {
  // The vertex buffer is bound as two chunks of at most maxStorageBufferRange each.
  const uint64_t vertexBytes = sizeof(gpu::scene::Vertex);
  uint64_t chunk = ctx_.caps().maxStorageBufferRange / vertexBytes * vertexBytes;
  uint64_t size = a.vertices->size() / vertexBytes * vertexBytes;
  if (size > 2 * chunk)
    throw DeviceError("bvh: vertex buffer of " + std::to_string(size) + " bytes exceeds 2 x maxStorageBufferRange (" +
                      std::to_string(ctx_.caps().maxStorageBufferRange) + " bytes)");
  vk::BufferRange lo(*a.vertices, 0, std::min(size, chunk));
  vk::BufferRange hi = size > chunk ? vk::BufferRange(*a.vertices, chunk, size - chunk)
                                    : vk::BufferRange(*a.vertices, 0, vertexBytes);
  BuildPush push{a.triangleCount, static_cast<uint32_t>(std::min(size, chunk) / vertexBytes), 0, 0};
  vk::Binder(pipeline_)
      .setRange(bb::kBoundsBindingTriangles, *a.triangles, 0,
                uint64_t(a.triangleCount) * sizeof(gpu::scene::Triangle))
      .set(bb::kBoundsBindingVerticesLo, lo)
      .set(bb::kBoundsBindingVerticesHi, hi)
      .set(bb::kBoundsBindingPrims, a.prims)
      .set(bb::kBoundsBindingInfo, a.info)
      .bind(cmd, push);
  pipeline_.dispatch(cmd, groups(a.triangleCount));
  vk::computeBarrier(cmd);
}

MortonPass::MortonPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_morton, bb::kMortonBindingCount, sizeof(BuildPush)) {}

void MortonPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder(pipeline_)
      .set(bb::kMortonBindingPrims, a.prims)
      .set(bb::kMortonBindingInfo, a.info)
      .set(bb::kMortonBindingKeys, a.keys)
      .set(bb::kMortonBindingValues, a.values)
      .bind(cmd, BuildPush{a.triangleCount, 0, 0, 0});
  pipeline_.dispatch(cmd, groups(a.triangleCount));
  vk::computeBarrier(cmd);
}

ExclusiveScan::ExclusiveScan(const vk::Context& ctx)
    : reduce_(ctx, shaders::Id::bvh_scan_reduce, bb::kScanBindingCount, sizeof(BuildPush)),
      top_(ctx, shaders::Id::bvh_scan_top, bb::kScanBindingCount, sizeof(BuildPush)),
      apply_(ctx, shaders::Id::bvh_scan_apply, bb::kScanBindingCount, sizeof(BuildPush)) {}

uint64_t ExclusiveScan::partialsBytes(uint32_t count) {
  return 4ull * std::max<uint64_t>(1, vk::groupCount(count, bb::kScanSegment));
}

void ExclusiveScan::record(VkCommandBuffer cmd, const Args& a) const {
  uint32_t segments = vk::groupCount(a.count, bb::kScanSegment);
  BuildPush push{a.count, segments, 0, 0};
  auto bind = [&](const vk::ComputePipeline& p) {
    vk::Binder(p)
        .set(bb::kScanBindingData, a.data)
        .set(bb::kScanBindingPartials, a.partials)
        .bind(cmd, push);
  };
  bind(reduce_);
  reduce_.dispatch(cmd, groups(segments));
  vk::computeBarrier(cmd);
  bind(top_);
  top_.dispatch(cmd, 1);
  vk::computeBarrier(cmd);
  bind(apply_);
  apply_.dispatch(cmd, groups(segments));
  vk::computeBarrier(cmd);
}

RadixSort::RadixSort(const vk::Context& ctx)
    : histogram_(ctx, shaders::Id::bvh_radix_histogram, bb::kRadixHistogramBindingCount, sizeof(BuildPush)),
      scatter_(ctx, shaders::Id::bvh_radix_scatter, bb::kRadixScatterBindingCount, sizeof(BuildPush)),
      scan_(ctx) {}

uint64_t RadixSort::histogramBytes(uint32_t count) {
  return 4ull * bb::kRadixBins * std::max<uint64_t>(1, vk::groupCount(count, bb::kRadixChunk));
}

void RadixSort::record(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  uint32_t chunks = vk::groupCount(a.count, bb::kRadixChunk);
  uint32_t histWords = chunks * bb::kRadixBins;
  vk::BufferRange keys[2] = {a.keys, a.keysTmp}, values[2] = {a.values, a.valuesTmp};
  static_assert((bb::kRadixKeyBits + bb::kRadixBits - 1) / bb::kRadixBits % 2 == 0,
                "an even number of rounds leaves the result in keys/values");
  int src = 0;
  for (uint32_t shift = 0; shift < bb::kRadixKeyBits; shift += bb::kRadixBits, src ^= 1) {
    BuildPush push{a.count, shift, chunks, 0};
    {
      vk::TimedScope scope(timer, cmd, "bvh_radix_histogram");
      vk::Binder(histogram_)
          .set(bb::kRadixBindingKeysIn, keys[src])
          .set(bb::kRadixBindingValuesIn, values[src])
          .set(bb::kRadixBindingHist, a.histogram)
          .bind(cmd, push);
      histogram_.dispatch(cmd, groups(chunks));
      vk::computeBarrier(cmd);
    }
    {
      vk::TimedScope scope(timer, cmd, "bvh_scan");
      scan_.record(cmd, {a.histogram, a.partials, histWords});
    }
    vk::TimedScope scope(timer, cmd, "bvh_radix_scatter");
    vk::Binder(scatter_)
        .set(bb::kRadixBindingKeysIn, keys[src])
        .set(bb::kRadixBindingValuesIn, values[src])
        .set(bb::kRadixBindingHist, a.histogram)
        .set(bb::kRadixBindingKeysOut, keys[src ^ 1])
        .set(bb::kRadixBindingValuesOut, values[src ^ 1])
        .bind(cmd, push);
    scatter_.dispatch(cmd, groups(chunks));
    vk::computeBarrier(cmd);
  }
}

LbvhPass::LbvhPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_lbvh, bb::kLbvhBindingCount, sizeof(BuildPush)) {}

void LbvhPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder(pipeline_)
      .set(bb::kLbvhBindingKeys, a.keys)
      .set(bb::kLbvhBindingValues, a.values)
      .set(bb::kLbvhBindingPrims, a.prims)
      .set(bb::kLbvhBindingInterior, a.interior)
      .set(bb::kLbvhBindingLeaves, a.leaves)
      .bind(cmd, BuildPush{a.triangleCount, 0, 0, 0});
  pipeline_.dispatch(cmd, groups(a.triangleCount));
  vk::computeBarrier(cmd);
}

RefitPass::RefitPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_refit, bb::kClimbBindingCount, sizeof(BuildPush), climbSpec(ctx, 0)) {}

void RefitPass::record(VkCommandBuffer cmd, const Args& a) const {
  vkCmdFillBuffer(cmd, a.counters->handle(), 0, VK_WHOLE_SIZE, 0);
  vk::transferBarrier(cmd);
  vk::Binder(pipeline_)
      .set(bb::kClimbBindingInterior, a.interior)
      .set(bb::kClimbBindingLeaves, a.leaves)
      .set(bb::kClimbBindingCounters, *a.counters)
      .bind(cmd, BuildPush{a.triangleCount, 0, 0, 0});
  pipeline_.dispatch(cmd, groups(a.triangleCount));
  vk::computeBarrier(cmd);
}

TreeletPass::TreeletPass(const vk::Context& ctx, uint32_t treeletLeaves)
    : count_(ctx, shaders::Id::bvh_treelet_count, bb::kTreeletBindingCount, sizeof(BuildPush), climbSpec(ctx, 0)),
      plan_(ctx, shaders::Id::bvh_treelet_plan, bb::kTreeletBindingCount, sizeof(BuildPush), climbSpec(ctx, 0)),
      scatter_(ctx, shaders::Id::bvh_treelet_scatter, bb::kTreeletBindingCount, sizeof(BuildPush), climbSpec(ctx, 0)),
      treelet_(ctx, shaders::Id::bvh_treelet, bb::kTreeletBindingCount, sizeof(BuildPush), climbSpec(ctx, treeletLeaves)) {
  if (treeletLeaves < 3 || treeletLeaves > bb::kTreeletMaxLeaves)
    throw InputError("bvh: treelet size " + std::to_string(treeletLeaves) + " outside 3.." +
                     std::to_string(bb::kTreeletMaxLeaves));
}

uint64_t TreeletPass::scheduleBytes() {
  return bb::kTreeletMaxLevels * (sizeof(bb::TreeletLevel) + sizeof(bb::DispatchArgs));
}

void TreeletPass::record(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  const uint32_t interior = a.triangleCount - 1;
  std::optional<vk::TimedScope> scope;
  scope.emplace(timer, cmd, "bvh_treelet_schedule");
  vkCmdFillBuffer(cmd, a.schedule->handle(), 0, VK_WHOLE_SIZE, 0);
  vk::transferBarrier(cmd);
  BuildPush push{a.triangleCount, a.minTriangles, 0, 0};
  // The four treelet pipelines bind the same buffers at the same slots.
  auto binder = [&](const vk::ComputePipeline& p) {
    vk::Binder b(p);
    b.set(bb::kClimbBindingInterior, a.interior)
        .set(bb::kClimbBindingLeaves, a.leaves)
        .set(bb::kClimbBindingCounters, a.counters)
        .set(bb::kTreeletBindingSchedule, *a.schedule)
        .set(bb::kTreeletBindingNodeList, a.nodeList);
    return b;
  };
  binder(count_).bind(cmd, push);
  count_.dispatch(cmd, groups(interior));
  vk::computeBarrier(cmd);
  binder(plan_).bind(cmd, push);
  plan_.dispatch(cmd, 1);
  vk::computeBarrier(cmd);
  binder(scatter_).bind(cmd, push);
  scatter_.dispatch(cmd, groups(interior));
  vk::computeBarrier(cmd);
  scope.reset();
  scope.emplace(timer, cmd, "bvh_treelet");
  // Height 0 holds no restructurable node (leaves and collapsed subtrees).
  const uint64_t argsOffset = bb::kTreeletMaxLevels * sizeof(bb::TreeletLevel);
  const vk::Binder treelet = binder(treelet_);
  for (uint32_t h = 1; h < bb::kTreeletMaxLevels; ++h) {
    treelet.bind(cmd, BuildPush{a.triangleCount, h, 0, 0});
    treelet_.dispatchIndirect(cmd, *a.schedule, argsOffset + h * sizeof(bb::DispatchArgs));
    vk::computeBarrier(cmd);
  }
}

EmitPass::EmitPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_emit, bb::kEmitBindingCount, sizeof(BuildPush)) {}

void EmitPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder(pipeline_)
      .set(bb::kEmitBindingInterior, a.interior)
      .set(bb::kEmitBindingLeaves, a.leaves)
      .set(bb::kEmitBindingPrims, a.prims)
      .set(bb::kEmitBindingInfo, a.info)
      .set(bb::kEmitBindingNodes, a.nodes)
      .set(bb::kEmitBindingLeafTriangles, a.leafTriangles)
      .bind(cmd, BuildPush{a.triangleCount, 0, 0, 0});
  pipeline_.dispatch(cmd, groups(std::max<uint32_t>(a.triangleCount - 1, 1)));
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
