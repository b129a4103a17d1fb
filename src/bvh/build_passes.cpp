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

// One invocation per item in rows of at most kMaxGroupsX groups (bvhBuildItem in GLSL), with
// as few groups past `items` as the row count allows.
void dispatchItems(const vk::ComputePipeline& p, VkCommandBuffer cmd, uint64_t items) {
  uint32_t g = groups(items);
  uint32_t rows = (g + bb::kMaxGroupsX - 1) / bb::kMaxGroupsX;
  p.dispatch(cmd, (g + rows - 1) / rows, rows);
}

glm::uvec2 address(const vk::BufferRange& r) {
  VkDeviceAddress a = r.buffer->deviceAddress() + r.offset;
  return {uint32_t(a), uint32_t(a >> 32)};
}
glm::uvec2 address(const vk::Buffer* b) { return address(vk::BufferRange(*b)); }

BuildPush push(uint32_t triangleCount, uint32_t param, const bb::BuildArrays& arrays = {}) {
  BuildPush p{};
  p.triangleCount = triangleCount;
  p.param = param;
  p.arrays = arrays;
  return p;
}
}  // namespace

BoundsPass::BoundsPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_bounds, bb::kBoundsBindingCount, sizeof(BuildPush)) {}

void BoundsPass::record(VkCommandBuffer cmd, const Args& a) const {
  bb::BuildArrays arrays{};
  arrays.triangles = address(a.triangles);
  arrays.vertices = address(a.vertices);
  arrays.prims = address(a.prims);
  vk::Binder(pipeline_).set(bb::kBoundsBindingInfo, a.info).bind(cmd, push(a.triangleCount, 0, arrays));
  dispatchItems(pipeline_, cmd, a.triangleCount);
  vk::computeBarrier(cmd);
}

MortonPass::MortonPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_morton, bb::kMortonBindingCount, sizeof(BuildPush)) {}

void MortonPass::record(VkCommandBuffer cmd, const Args& a) const {
  bb::BuildArrays arrays{};
  arrays.prims = address(a.prims);
  vk::Binder(pipeline_)
      .set(bb::kMortonBindingInfo, a.info)
      .set(bb::kMortonBindingKeys, a.keys)
      .set(bb::kMortonBindingValues, a.values)
      .bind(cmd, push(a.triangleCount, 0, arrays));
  dispatchItems(pipeline_, cmd, a.triangleCount);
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
  auto bind = [&](const vk::ComputePipeline& p) {
    vk::Binder(p)
        .set(bb::kScanBindingData, a.data)
        .set(bb::kScanBindingPartials, a.partials)
        .bind(cmd, push(a.count, segments));
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
    BuildPush pushed = push(a.count, shift);
    pushed.param2 = chunks;
    {
      vk::TimedScope scope(timer, cmd, "bvh_radix_histogram");
      vk::Binder(histogram_)
          .set(bb::kRadixBindingKeysIn, keys[src])
          .set(bb::kRadixBindingValuesIn, values[src])
          .set(bb::kRadixBindingHist, a.histogram)
          .bind(cmd, pushed);
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
        .bind(cmd, pushed);
    scatter_.dispatch(cmd, groups(chunks));
    vk::computeBarrier(cmd);
  }
}

LbvhPass::LbvhPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_lbvh, bb::kLbvhBindingCount, sizeof(BuildPush)) {}

void LbvhPass::record(VkCommandBuffer cmd, const Args& a) const {
  bb::BuildArrays arrays{};
  arrays.prims = address(a.prims);
  arrays.interior = address(a.interior);
  arrays.leaves = address(a.leaves);
  vk::Binder(pipeline_)
      .set(bb::kLbvhBindingKeys, a.keys)
      .set(bb::kLbvhBindingValues, a.values)
      .bind(cmd, push(a.triangleCount, 0, arrays));
  dispatchItems(pipeline_, cmd, a.triangleCount);
  vk::computeBarrier(cmd);
}

RefitPass::RefitPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_refit, bb::kClimbBindingCount, sizeof(BuildPush), climbSpec(ctx, 0)) {}

void RefitPass::record(VkCommandBuffer cmd, const Args& a) const {
  vkCmdFillBuffer(cmd, a.counters->handle(), 0, VK_WHOLE_SIZE, 0);
  vk::transferBarrier(cmd);
  bb::BuildArrays arrays{};
  arrays.interior = address(a.interior);
  arrays.leaves = address(a.leaves);
  vk::Binder(pipeline_)
      .set(bb::kClimbBindingCounters, *a.counters)
      .bind(cmd, push(a.triangleCount, 0, arrays));
  dispatchItems(pipeline_, cmd, a.triangleCount);
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
  bb::BuildArrays arrays{};
  arrays.interior = address(a.interior);
  arrays.leaves = address(a.leaves);
  const BuildPush schedulePush = push(a.triangleCount, a.minTriangles, arrays);
  // The four treelet pipelines bind the same buffers at the same slots.
  auto binder = [&](const vk::ComputePipeline& p) {
    vk::Binder b(p);
    b.set(bb::kClimbBindingCounters, a.counters)
        .set(bb::kTreeletBindingSchedule, *a.schedule)
        .set(bb::kTreeletBindingNodeList, a.nodeList);
    return b;
  };
  binder(count_).bind(cmd, schedulePush);
  dispatchItems(count_, cmd, interior);
  vk::computeBarrier(cmd);
  binder(plan_).bind(cmd, schedulePush);
  plan_.dispatch(cmd, 1);
  vk::computeBarrier(cmd);
  binder(scatter_).bind(cmd, schedulePush);
  dispatchItems(scatter_, cmd, interior);
  vk::computeBarrier(cmd);
  scope.reset();
  scope.emplace(timer, cmd, "bvh_treelet");
  // Height 0 holds no restructurable node (leaves and collapsed subtrees).
  const uint64_t argsOffset = bb::kTreeletMaxLevels * sizeof(bb::TreeletLevel);
  const vk::Binder treelet = binder(treelet_);
  for (uint32_t h = 1; h < bb::kTreeletMaxLevels; ++h) {
    treelet.bind(cmd, push(a.triangleCount, h, arrays));
    treelet_.dispatchIndirect(cmd, *a.schedule, argsOffset + h * sizeof(bb::DispatchArgs));
    vk::computeBarrier(cmd);
  }
}

EmitPass::EmitPass(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::bvh_emit, bb::kEmitBindingCount, sizeof(BuildPush)) {}

void EmitPass::record(VkCommandBuffer cmd, const Args& a) const {
  bb::BuildArrays arrays{};
  arrays.interior = address(a.interior);
  arrays.leaves = address(a.leaves);
  arrays.prims = address(a.prims);
  arrays.nodes = address(a.nodes);
  arrays.leafTriangles = address(a.leafTriangles);
  vk::Binder(pipeline_).set(bb::kEmitBindingInfo, a.info).bind(cmd, push(a.triangleCount, 0, arrays));
  dispatchItems(pipeline_, cmd, std::max<uint32_t>(a.triangleCount - 1, 1));
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
