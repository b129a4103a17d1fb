#include "bvh/build_passes.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <string>

#include "bvh/bvh.h"
#include "common/error.h"
#include "vk/binder.h"
#include "vk/timer.h"

namespace osr::bvh {

namespace bb = gpu::bvh_build;
using bb::BuildPush;

namespace {
// See climbFence() in shaders/lib/bvh_build_nodes.glsl for why CPU devices run without fences.
std::vector<vk::SpecConstant> climbSpec(const vk::Context& ctx, bool byAddress, uint32_t treeletLeaves) {
  std::vector<vk::SpecConstant> spec = {vk::specUint(bb::kClimbSpecFences, ctx.caps().isCpu() ? 0u : 1u),
                                        vk::specUint(bb::kBuildSpecByAddress, byAddress ? 1u : 0u)};
  if (treeletLeaves) spec.push_back(vk::specUint(bb::kTreeletSpecLeaves, treeletLeaves));
  return spec;
}
std::vector<vk::SpecConstant> arraySpec(bool byAddress) {
  return {vk::specUint(bb::kBuildSpecByAddress, byAddress ? 1u : 0u)};
}
uint32_t groups(uint64_t items) { return vk::groupCount(std::max<uint64_t>(items, 1), bb::kWorkgroupSize); }

// One invocation per item in rows of at most kMaxGroupsX groups (bvhBuildItem in GLSL), with
// as few groups past `items` as the row count allows.
void dispatchItems(const vk::ComputePipeline& p, VkCommandBuffer cmd, uint64_t items) {
  uint32_t g = groups(items);
  uint32_t rows = (g + bb::kMaxGroupsX - 1) / bb::kMaxGroupsX;
  p.dispatch(cmd, (g + rows - 1) / rows, rows);
}

BuildPush push(uint32_t triangleCount, uint32_t param) {
  BuildPush p{};
  p.triangleCount = triangleCount;
  p.param = param;
  return p;
}

// The arrays in slot order (kBuildBinding*).
std::array<vk::BufferRange, bb::kBuildArrayBindingCount> slots(const BuildArrayBuffers& a) {
  std::array<vk::BufferRange, bb::kBuildArrayBindingCount> s;
  s[bb::kBuildBindingTriangles] = a.triangles;
  s[bb::kBuildBindingVertices] = a.vertices;
  s[bb::kBuildBindingPrims] = a.prims;
  s[bb::kBuildBindingInterior] = a.interior;
  s[bb::kBuildBindingLeaves] = a.leaves;
  s[bb::kBuildBindingNodes] = a.nodes;
  s[bb::kBuildBindingLeafTriangles] = a.leafTriangles;
  s[bb::kBuildBindingTraversalNodes] = a.traversalNodes;
  return s;
}

// Sets the array slots and returns the push block for (triangleCount, param). By address, the
// push block carries the addresses and each slot only the first maxStorageBufferRange bytes of
// its array (the shader reads none of it); a slot whose array the pass does not use (unset)
// takes another array's range.
BuildPush bindArrays(vk::Binder& binder, const ArrayAccess& access, const BuildArrayBuffers& a,
                     uint32_t triangleCount, uint32_t param) {
  const auto ranges = slots(a);
  const auto filler = std::find_if(ranges.begin(), ranges.end(), [](const vk::BufferRange& r) { return r.buffer; });
  if (filler == ranges.end()) throw DeviceError("bvh: a build pass got none of its arrays");
  const VkDeviceSize limit = access.ctx->caps().maxStorageBufferRange / 16 * 16;
  BuildPush p = push(triangleCount, param);
  glm::uvec2* addresses = &p.arrays.triangles;  // BuildArrays: one uvec2 per slot, in slot order
  static_assert(sizeof(bb::BuildArrays) >= bb::kBuildArrayBindingCount * sizeof(glm::uvec2));
  static_assert(offsetof(bb::BuildArrays, traversalNodes) == bb::kBuildBindingTraversalNodes * sizeof(glm::uvec2));
  for (uint32_t i = 0; i < bb::kBuildArrayBindingCount; ++i) {
    vk::BufferRange r = ranges[i].buffer ? ranges[i] : *filler;
    if (access.byAddress) {
      if (ranges[i].buffer) {
        VkDeviceAddress at = r.buffer->deviceAddress() + r.offset;
        addresses[i] = {uint32_t(at), uint32_t(at >> 32)};
      }
      r.size = std::min(r.bytes(), limit);
    }
    binder.set(i, r);
  }
  return p;
}
// Storage-buffer slots but for uniform texel buffers at `texelSlots`.
std::vector<VkDescriptorType> storageAndTexelTypes(uint32_t bindingCount, std::initializer_list<uint32_t> texelSlots) {
  std::vector<VkDescriptorType> t(bindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  for (uint32_t slot : texelSlots) t[slot] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}
// Storage-buffer slots but for the kBuildTexelBindingCount texel slots from `texelBase`.
std::vector<VkDescriptorType> texelTypes(uint32_t bindingCount, uint32_t texelBase) {
  std::vector<VkDescriptorType> t(bindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  for (uint32_t k = 0; k < bb::kBuildTexelBindingCount; ++k) t[texelBase + k] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}
// `spec` plus kBuildSpecTexels: texel reads where a view reaches as far as the largest array
// read (BvhBuildNode[N]) can be, one binding's worth or, by address, the triangle limit's.
std::vector<vk::SpecConstant> texelSpec(const vk::Context& ctx, bool byAddress, std::vector<vk::SpecConstant> spec) {
  const vk::Capabilities& caps = ctx.caps();
  uint64_t arrayBytes = byAddress ? uint64_t(triangleLimit(ctx).triangles) * sizeof(bb::BvhBuildNode)
                                  : uint64_t(caps.maxStorageBufferRange);
  spec.push_back(vk::specUint(bb::kBuildSpecTexels, uint64_t(caps.maxTexelBufferElements) * 16 >= arrayBytes ? 1u : 0u));
  return spec;
}
// Whether an R32UI view reaches as far as a binding of the 4-byte-per-item arrays (keys, slots)
// can (triangleLimit bounds them by maxStorageBufferRange): 128M texels on lavapipe against 32M.
bool wordTexelsCoverBindings(const vk::Context& ctx) {
  return uint64_t(ctx.caps().maxTexelBufferElements) * 4 >= ctx.caps().maxStorageBufferRange;
}
// The layout and spec of a pass that also reads one array of 4-byte items (keys, slots) through
// an R32UI view at binding `wordTexels`, switched by spec constant `wordSpec`.
std::vector<VkDescriptorType> wordTexelTypes(uint32_t bindingCount, uint32_t texelBase, uint32_t wordTexels) {
  std::vector<VkDescriptorType> t = texelTypes(bindingCount, texelBase);
  t[wordTexels] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}
std::vector<vk::SpecConstant> wordTexelSpec(const vk::Context& ctx, bool byAddress, uint32_t wordSpec) {
  std::vector<vk::SpecConstant> spec = texelSpec(ctx, byAddress, arraySpec(byAddress));
  spec.push_back(vk::specUint(wordSpec, wordTexelsCoverBindings(ctx) ? 1u : 0u));
  return spec;
}
void bindTexels(vk::Binder& binder, uint32_t texelBase, const BuildTexelViews& views) {
  binder.setTexel(texelBase + bb::kBuildTexelInterior, views.interior)
      .setTexel(texelBase + bb::kBuildTexelLeaves, views.leaves)
      .setTexel(texelBase + bb::kBuildTexelPrims, views.prims);
}
// A bottom-up climb (lib/bvh_build_nodes.glsl): zeroes the climb counters, binds the arrays,
// texels and counters (beside the pass's own slots already in `binder`) and runs one invocation
// per leaf.
void recordClimb(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, vk::Binder& binder, const ArrayAccess& access,
                 const BuildArrayBuffers& arrays, const BuildTexelViews& texels, uint32_t texelBase,
                 const vk::BufferRange& counters, uint32_t triangleCount) {
  vkCmdFillBuffer(cmd, counters.buffer->handle(), counters.offset, counters.bytes(), 0);
  vk::transferBarrier(cmd);
  BuildPush p = bindArrays(binder, access, arrays, triangleCount, 0);
  bindTexels(binder, texelBase, texels);
  binder.set(bb::kClimbBindingCounters, counters).bind(cmd, p);
  dispatchItems(pipeline, cmd, triangleCount);
  vk::computeBarrier(cmd);
}
// One indirect dispatch per level in [first, levels) of a schedule laid out as
// LevelList[levels] then DispatchArgs[levels] (the treelet rounds' by height, the emit's by
// depth), with push.param = the level, each followed by a barrier.
void dispatchLevels(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, const vk::Binder& binder, BuildPush push,
                    const vk::Buffer& schedule, uint32_t first, uint32_t levels) {
  const uint64_t argsOffset = levels * sizeof(bb::LevelList);
  for (uint32_t level = first; level < levels; ++level) {
    push.param = level;
    binder.bind(cmd, push);
    pipeline.dispatchIndirect(cmd, schedule, argsOffset + level * sizeof(bb::DispatchArgs));
    vk::computeBarrier(cmd);
  }
}
}  // namespace

bool BuildArrayBuffers::pastOneBinding(const vk::Context& ctx) const {
  for (const vk::BufferRange& r : slots(*this))
    if (r.buffer && r.bytes() > ctx.caps().maxStorageBufferRange) return true;
  return false;
}

BoundsPass::BoundsPass(const vk::Context& ctx, bool byAddress) : access_{&ctx, byAddress} {}

void BoundsPass::record(VkCommandBuffer cmd, const Args& a) const {
  const bool sceneTexels = a.triangleTexels && a.vertexTexels;
  std::optional<vk::ComputePipeline>& pipeline = pipelines_[sceneTexels ? 1 : 0];
  if (!pipeline) {
    std::vector<vk::SpecConstant> spec = arraySpec(access_.byAddress);
    spec.push_back(vk::specUint(bb::kBoundsSpecSceneTexels, sceneTexels ? 1u : 0u));
    pipeline.emplace(*access_.ctx, shaders::Id::bvh_bounds,
                     storageAndTexelTypes(bb::kBoundsBindingCount, {bb::kBoundsBindingTriangleTexels, bb::kBoundsBindingVertexTexels}),
                     sizeof(BuildPush), spec);
  }
  vk::Binder binder(*pipeline);
  BuildPush p = bindArrays(binder, access_, *a.arrays, a.triangleCount, 0);
  binder.set(bb::kBoundsBindingInfo, a.info)
      .setTexel(bb::kBoundsBindingTriangleTexels, sceneTexels ? a.triangleTexels : a.unusedTexels)
      .setTexel(bb::kBoundsBindingVertexTexels, sceneTexels ? a.vertexTexels : a.unusedTexels)
      .bind(cmd, p);
  dispatchItems(*pipeline, cmd, a.triangleCount);
  vk::computeBarrier(cmd);
}

MortonPass::MortonPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(ctx, shaders::Id::bvh_morton, texelTypes(bb::kMortonBindingCount, bb::kMortonBindingTexels),
                sizeof(BuildPush), texelSpec(ctx, byAddress, arraySpec(byAddress))) {}

void MortonPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder binder(pipeline_);
  BuildPush p = bindArrays(binder, access_, *a.arrays, a.triangleCount, 0);
  binder.set(bb::kMortonBindingInfo, a.info).set(bb::kMortonBindingKeys, a.keys).set(bb::kMortonBindingValues, a.values);
  bindTexels(binder, bb::kMortonBindingTexels, *a.texels);
  binder.bind(cmd, p);
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

namespace {
std::vector<VkDescriptorType> radixTypes() {
  return storageAndTexelTypes(bb::kRadixBindingCount, {bb::kRadixBindingKeyTexelsIn, bb::kRadixBindingValueTexelsIn});
}
std::vector<vk::SpecConstant> radixSpec(const vk::Context& ctx) {
  return {vk::specUint(bb::kRadixSpecTexels, wordTexelsCoverBindings(ctx) ? 1u : 0u)};
}
}  // namespace

RadixSort::RadixSort(const vk::Context& ctx)
    : histogram_(ctx, shaders::Id::bvh_radix_histogram, radixTypes(), sizeof(BuildPush), radixSpec(ctx)),
      scatter_(ctx, shaders::Id::bvh_radix_scatter, radixTypes(), sizeof(BuildPush), radixSpec(ctx)),
      scan_(ctx) {}

uint64_t RadixSort::histogramBytes(uint32_t count) {
  return 4ull * bb::kRadixBins * std::max<uint64_t>(1, vk::groupCount(count, bb::kRadixChunk));
}

void RadixSort::record(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  uint32_t chunks = vk::groupCount(a.count, bb::kRadixChunk);
  uint32_t histWords = chunks * bb::kRadixBins;
  vk::BufferRange keys[2] = {a.keys, a.keysTmp}, values[2] = {a.values, a.valuesTmp};
  VkBufferView keyTexels[2] = {a.keyTexels, a.keyTmpTexels}, valueTexels[2] = {a.valueTexels, a.valueTmpTexels};
  static_assert((bb::kRadixKeyBits + bb::kRadixBits - 1) / bb::kRadixBits % 2 == 0,
                "an even number of rounds leaves the result in keys/values");
  int src = 0;
  for (uint32_t shift = 0; shift < bb::kRadixKeyBits; shift += bb::kRadixBits, src ^= 1) {
    BuildPush pushed = push(a.count, shift);
    pushed.param2 = chunks;
    // Both pipelines bind the same buffers at the same slots.
    auto bind = [&](const vk::ComputePipeline& p) {
      vk::Binder(p)
          .set(bb::kRadixBindingKeysIn, keys[src])
          .set(bb::kRadixBindingValuesIn, values[src])
          .set(bb::kRadixBindingHist, a.histogram)
          .set(bb::kRadixBindingKeysOut, keys[src ^ 1])
          .set(bb::kRadixBindingValuesOut, values[src ^ 1])
          .setTexel(bb::kRadixBindingKeyTexelsIn, keyTexels[src])
          .setTexel(bb::kRadixBindingValueTexelsIn, valueTexels[src])
          .bind(cmd, pushed);
    };
    {
      vk::TimedScope scope(timer, cmd, "bvh_radix_histogram");
      bind(histogram_);
      histogram_.dispatch(cmd, groups(chunks));
      vk::computeBarrier(cmd);
    }
    {
      vk::TimedScope scope(timer, cmd, "bvh_scan");
      scan_.record(cmd, {a.histogram, a.partials, histWords});
    }
    vk::TimedScope scope(timer, cmd, "bvh_radix_scatter");
    bind(scatter_);
    scatter_.dispatch(cmd, groups(chunks));
    vk::computeBarrier(cmd);
  }
}

LbvhPass::LbvhPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(ctx, shaders::Id::bvh_lbvh,
                wordTexelTypes(bb::kLbvhBindingCount, bb::kLbvhBindingTexels, bb::kLbvhBindingKeyTexels),
                sizeof(BuildPush), wordTexelSpec(ctx, byAddress, bb::kLbvhSpecKeyTexels)) {}

void LbvhPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder binder(pipeline_);
  BuildPush p = bindArrays(binder, access_, *a.arrays, a.triangleCount, 0);
  binder.set(bb::kLbvhBindingKeys, a.keys)
      .set(bb::kLbvhBindingValues, a.values)
      .setTexel(bb::kLbvhBindingKeyTexels, a.keyTexels);
  bindTexels(binder, bb::kLbvhBindingTexels, *a.texels);
  binder.bind(cmd, p);
  dispatchItems(pipeline_, cmd, a.triangleCount);
  vk::computeBarrier(cmd);
}

RefitPass::RefitPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(ctx, shaders::Id::bvh_refit, texelTypes(bb::kRefitBindingCount, bb::kRefitBindingTexels), sizeof(BuildPush),
                texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, 0))) {}

void RefitPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder binder(pipeline_);
  recordClimb(cmd, pipeline_, binder, access_, *a.arrays, *a.texels, bb::kRefitBindingTexels, *a.counters, a.triangleCount);
}

namespace {
std::vector<VkDescriptorType> treeletTypes() {
  return wordTexelTypes(bb::kTreeletBindingCount, bb::kTreeletBindingTexels, bb::kTreeletBindingSubtreeNodes + 1);
}
}  // namespace

TreeletPass::TreeletPass(const vk::Context& ctx, uint32_t treeletLeaves, bool byAddress)
    : access_{&ctx, byAddress},
      count_(ctx, shaders::Id::bvh_treelet_count, treeletTypes(), sizeof(BuildPush),
             texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, 0))),
      plan_(ctx, shaders::Id::bvh_treelet_plan, treeletTypes(), sizeof(BuildPush), climbSpec(ctx, byAddress, 0)),
      scatter_(ctx, shaders::Id::bvh_treelet_scatter, treeletTypes(), sizeof(BuildPush),
               texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, 0))),
      treelet_(ctx, shaders::Id::bvh_treelet, treeletTypes(), sizeof(BuildPush),
               texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, treeletLeaves))) {
  if (treeletLeaves < 3 || treeletLeaves > bb::kTreeletMaxLeaves)
    throw InputError("bvh: treelet size " + std::to_string(treeletLeaves) + " outside 3.." +
                     std::to_string(bb::kTreeletMaxLeaves));
}

uint64_t TreeletPass::scheduleBytes() {
  return bb::kTreeletMaxLevels * (sizeof(bb::LevelList) + sizeof(bb::DispatchArgs)) +
         bb::kTreeletBanks * bb::kTreeletMaxLevels * sizeof(glm::uvec2);
}

void TreeletPass::record(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  const uint32_t interior = a.triangleCount - 1;
  std::optional<vk::TimedScope> scope;
  scope.emplace(timer, cmd, "bvh_treelet_schedule");
  vkCmdFillBuffer(cmd, a.schedule->handle(), 0, VK_WHOLE_SIZE, 0);
  vk::transferBarrier(cmd);
  BuildPush schedulePush{};
  // The four treelet pipelines bind the same buffers at the same slots.
  auto binder = [&](const vk::ComputePipeline& p) {
    vk::Binder b(p);
    schedulePush = bindArrays(b, access_, *a.arrays, a.triangleCount, a.minTriangles);
    b.set(bb::kClimbBindingCounters, a.counters)
        .set(bb::kTreeletBindingSchedule, *a.schedule)
        .set(bb::kTreeletBindingNodeList, a.nodeList)
        .set(bb::kTreeletBindingSubtreeNodes, a.subtreeNodes)
        .setTexel(bb::kTreeletBindingSubtreeNodes + 1, a.subtreeNodeTexels);
    bindTexels(b, bb::kTreeletBindingTexels, *a.texels);
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
  const vk::Binder treelet = binder(treelet_);
  BuildPush treeletPush = schedulePush;
  treeletPush.param2 = a.countNodes ? bb::kTreeletCountNodes : 0u;
  dispatchLevels(cmd, treelet_, treelet, treeletPush, *a.schedule, 1, bb::kTreeletMaxLevels);
}

SubtreeCountPass::SubtreeCountPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(ctx, shaders::Id::bvh_subtree_count, texelTypes(bb::kSubtreeCountBindingCount, bb::kSubtreeCountBindingTexels),
                sizeof(BuildPush), texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, 0))) {}

void SubtreeCountPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder binder(pipeline_);
  binder.set(bb::kSubtreeCountBindingNodes, a.subtreeNodes);
  recordClimb(cmd, pipeline_, binder, access_, *a.arrays, *a.texels, bb::kSubtreeCountBindingTexels, a.counters,
              a.triangleCount);
}

namespace {
std::vector<VkDescriptorType> plocTypes() {
  std::vector<VkDescriptorType> t = wordTexelTypes(bb::kPlocBindingCount, bb::kPlocBindingTexels, bb::kPlocBindingClusterTexels);
  for (uint32_t slot : {bb::kPlocBindingNearestTexels, bb::kPlocBindingSubtreeNodes + 1, bb::kPlocBindingClusterTexels1})
    t[slot] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}
std::vector<vk::SpecConstant> plocSpec(const vk::Context& ctx) { return texelSpec(ctx, false, arraySpec(false)); }
}  // namespace

PlocPass::PlocPass(const vk::Context& ctx)
    : access_{&ctx, false},
      init_(ctx, shaders::Id::bvh_ploc_init, plocTypes(), sizeof(BuildPush), plocSpec(ctx)),
      nearest_(ctx, shaders::Id::bvh_ploc_nearest, plocTypes(), sizeof(BuildPush), plocSpec(ctx)),
      count_(ctx, shaders::Id::bvh_ploc_count, plocTypes(), sizeof(BuildPush), plocSpec(ctx)),
      plan_(ctx, shaders::Id::bvh_ploc_plan, plocTypes(), sizeof(BuildPush), plocSpec(ctx)),
      compact_(ctx, shaders::Id::bvh_ploc_compact, plocTypes(), sizeof(BuildPush), plocSpec(ctx)),
      merge_(ctx, shaders::Id::bvh_ploc_merge, plocTypes(), sizeof(BuildPush), plocSpec(ctx)),
      tail_(ctx, shaders::Id::bvh_ploc_tail, plocTypes(), sizeof(BuildPush), plocSpec(ctx)),
      root_(ctx, shaders::Id::bvh_ploc_root, plocTypes(), sizeof(BuildPush), plocSpec(ctx)) {
  if (localMergesSupported(ctx))
    local_.emplace(ctx, shaders::Id::bvh_ploc_local, plocTypes(), sizeof(BuildPush), plocSpec(ctx));
}

bool PlocPass::localMergesSupported(const vk::Context& ctx) {
  return ctx.caps().subgroupShuffle && ctx.caps().subgroupSize % bb::kPlocLocalChunk == 0;
}

// Binds a PLOC pass: `in` as this iteration's clusters, `out` as the next.
vk::Binder PlocPass::binder(const vk::ComputePipeline& pipeline, const Args& a, uint32_t in, uint32_t out,
                            uint32_t parity, BuildPush& push) const {
  vk::Binder b(pipeline);
  push = bindArrays(b, access_, *a.arrays, a.triangleCount, parity);
  b.setTexel(bb::kPlocBindingClusterTexels, a.clusterTexels[in])
      .set(bb::kPlocBindingNextClusters, *a.clusters[out])
      .set(bb::kPlocBindingNearest, a.nearest)
      .setTexel(bb::kPlocBindingNearestTexels, a.nearestTexels)
      .set(bb::kPlocBindingPartials, a.partials)
      .set(bb::kPlocBindingState, *a.state)
      .set(bb::kPlocBindingValues, a.values)
      .set(bb::kPlocBindingPairs, a.pairs)
      .set(bb::kPlocBindingSubtreeNodes, a.subtreeNodes)
      .setTexel(bb::kPlocBindingSubtreeNodes + 1, a.subtreeNodeTexels)
      .set(bb::kPlocBindingTailClusters, a.tailClusters != 0 ? a.tailScratch : a.pairs)  // unread without a tail
      .setTexel(bb::kPlocBindingClusterTexels1, a.clusterTexels[1]);
  bindTexels(b, bb::kPlocBindingTexels, *a.texels);
  return b;
}

void PlocPass::record(VkCommandBuffer cmd, const Args& a, uint32_t iterations, vk::GpuTimer* timer) const {
  if (a.triangleCount < 2 || groups(a.triangleCount) > bb::kMaxGroupsX)
    throw DeviceError("bvh: PLOC builds 2 to " + std::to_string(uint64_t(bb::kMaxGroupsX) * bb::kWorkgroupSize) +
                      " triangles, not " + std::to_string(a.triangleCount));
  if (a.tailClusters != 0 && (a.tailCapacity > bb::kPlocTailCapacity || a.tailCapacity < std::min(a.tailClusters, a.triangleCount) ||
                              a.tailScratch.bytes() < 64ull * a.tailCapacity))
    throw DeviceError("bvh: PLOC's tail takes " + std::to_string(a.tailClusters) + " clusters, but has room for " +
                      std::to_string(a.tailCapacity));
  bb::PlocState initial{};
  initial.count = {a.triangleCount, 0};
  initial.args0 = {groups(a.triangleCount), 1, 1};  // bvh_ploc_local or the first iteration: always
  initial.args1 = {0, 1, 1};
  initial.clusterParity = 0;  // bvh_ploc_init's
  initial.tailClusters = a.tailClusters;
  vkCmdUpdateBuffer(cmd, a.state->handle(), 0, sizeof(initial), &initial);
  vk::transferBarrier(cmd);
  {
    vk::TimedScope scope(timer, cmd, "bvh_ploc_init");
    BuildPush p{};
    binder(init_, a, 1, 0, 0, p).bind(cmd, p);  // writes the first clusters, bound as the next
    dispatchItems(init_, cmd, a.triangleCount);
    vk::computeBarrier(cmd);
  }
  recordLocal(cmd, a, timer);
  recordIterations(cmd, a, iterations, timer);
  BuildPush p{};
  if (a.tailClusters != 0) {
    vk::TimedScope scope(timer, cmd, "bvh_ploc_tail");
    // Clusters of parity 0 at kPlocBindingClusterTexels, 1 at kPlocBindingClusterTexels1.
    const vk::Binder tail = binder(tail_, a, 0, 1, finalParity(a.localRounds, iterations), p);
    p.param2 = a.tailCapacity;
    tail.bind(cmd, p);
    tail_.dispatch(cmd, 1);
    vk::computeBarrier(cmd);
  }
  vk::TimedScope scope(timer, cmd, "bvh_ploc");  // with the iterations
  p = BuildPush{};
  binder(root_, a, 0, 1, 0, p).bind(cmd, p);
  root_.dispatch(cmd, 1);
  vk::computeBarrier(cmd);
}

void PlocPass::recordLocal(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  if (a.localRounds == 0) return;
  if (!local_)
    throw DeviceError("bvh: PLOC's local merges need subgroup shuffles, votes and ballots in subgroups of a multiple of " +
                      std::to_string(bb::kPlocLocalChunk));
  vk::TimedScope scope(timer, cmd, "bvh_ploc_local");
  for (uint32_t k = 0; k < a.localRounds; ++k) {
    const uint32_t parity = k & 1u;
    BuildPush p{};
    binder(*local_, a, parity, parity ^ 1u, parity, p).bind(cmd, p);
    local_->dispatchIndirect(cmd, *a.state, offsetof(bb::PlocState, args0) + parity * sizeof(bb::DispatchArgs));
    vk::computeBarrier(cmd);
  }
}

void PlocPass::recordIterations(VkCommandBuffer cmd, const Args& a, uint32_t iterations, vk::GpuTimer* timer) const {
  vk::TimedScope scope(timer, cmd, "bvh_ploc");
  static_assert(offsetof(bb::PlocState, args1) == offsetof(bb::PlocState, args0) + sizeof(bb::DispatchArgs));
  const uint64_t argsOffset = offsetof(bb::PlocState, args0);
  for (uint32_t k = 0; k < iterations; ++k) {
    const uint32_t parity = (a.localRounds + k) & 1u;  // reads clusters[parity], compacts into the other
    const uint64_t args = argsOffset + parity * sizeof(bb::DispatchArgs);
    for (const vk::ComputePipeline* pipeline : {&nearest_, &count_, &plan_, &compact_, &merge_}) {
      BuildPush p{};
      binder(*pipeline, a, parity, parity ^ 1u, parity, p).bind(cmd, p);
      if (pipeline == &plan_)
        plan_.dispatch(cmd, 1);
      else if (pipeline == &merge_)
        merge_.dispatchIndirect(cmd, *a.state, offsetof(bb::PlocState, pairArgs));
      else
        pipeline->dispatchIndirect(cmd, *a.state, args);
      vk::computeBarrier(cmd);
    }
  }
}

namespace {
std::vector<VkDescriptorType> emitTypes() {
  return wordTexelTypes(bb::kEmitBindingCount, bb::kEmitBindingTexels, bb::kEmitBindingSlotTexels);
}
}  // namespace

EmitPass::EmitPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      leaves_(ctx, shaders::Id::bvh_emit_leaves, emitTypes(), sizeof(BuildPush),
              wordTexelSpec(ctx, byAddress, bb::kEmitSpecSlotTexels)) {}

const vk::ComputePipeline& EmitPass::nodes(uint32_t forms, bool singleTriangle) const {
  std::optional<vk::ComputePipeline>& pipeline = nodes_[forms | (singleTriangle ? 4u : 0u)];
  if (!pipeline) {
    std::vector<vk::SpecConstant> spec = wordTexelSpec(*access_.ctx, access_.byAddress, bb::kEmitSpecSlotTexels);
    spec.push_back(vk::specUint(bb::kEmitSpecForms, forms));
    spec.push_back(vk::specUint(bb::kEmitSpecSingleTriangle, singleTriangle ? 1u : 0u));
    pipeline.emplace(*access_.ctx, shaders::Id::bvh_emit_nodes, emitTypes(), sizeof(BuildPush), spec);
  }
  return *pipeline;
}

uint64_t EmitPass::scheduleBytes() {
  return bb::kEmitMaxLevels * (sizeof(bb::LevelList) + sizeof(bb::DispatchArgs));
}

void EmitPass::record(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  const bool ordered = a.triangleCount > 1;  // one triangle: the root alone, no depths
  if (ordered) {
    // Depth 0 is the root alone, at position 0; every other depth starts empty (x = 0 groups).
    struct Schedule {
      bb::LevelList levels[bb::kEmitMaxLevels];
      bb::DispatchArgs args[bb::kEmitMaxLevels];
    } initial{};
    static_assert(sizeof(Schedule) == bb::kEmitMaxLevels * (sizeof(bb::LevelList) + sizeof(bb::DispatchArgs)));
    for (bb::DispatchArgs& d : initial.args) d = {0, 1, 1};
    initial.levels[0].count = 1;
    initial.args[0].x = 1;
    vkCmdUpdateBuffer(cmd, a.schedule->handle(), 0, sizeof(initial), &initial);
    vkCmdFillBuffer(cmd, a.positions.buffer->handle(), a.positions.offset, 4, 0);    // the root's position
    vkCmdFillBuffer(cmd, a.levelNodes.buffer->handle(), a.levelNodes.offset, 4, 0);  // depth 0: the root
    vkCmdFillBuffer(cmd, a.leafBases.buffer->handle(), a.leafBases.offset, 4, 0);    // the root's leaf base
    vk::transferBarrier(cmd);
  }
  BuildPush p{};
  // The two pipelines bind the same buffers at the same slots.
  auto binder = [&](const vk::ComputePipeline& pipeline) {
    vk::Binder b(pipeline);
    p = bindArrays(b, access_, *a.arrays, a.triangleCount, 0);
    b.set(bb::kEmitBindingInfo, a.info).set(bb::kEmitBindingSlots, a.slots).setTexel(bb::kEmitBindingSlotTexels, a.slotTexels);
    // One triangle: the order's buffers are unread, and the slots fill their slots.
    b.set(bb::kEmitBindingPositions, ordered ? a.positions : a.slots)
        .set(bb::kEmitBindingSubtreeNodes, ordered ? a.subtreeNodes : a.slots)
        .set(bb::kEmitBindingSchedule, ordered ? vk::BufferRange(*a.schedule) : a.slots)
        .set(bb::kEmitBindingLevelNodes, ordered ? a.levelNodes : a.slots)
        .set(bb::kEmitBindingLeafBases, ordered ? a.leafBases : a.slots);
    bindTexels(b, bb::kEmitBindingTexels, *a.texels);
    return b;
  };
  {
    vk::TimedScope scope(timer, cmd, "bvh_emit_nodes");
    const uint32_t forms = (a.exactNodes ? bb::kEmitExactNodes : 0u) | (a.quantizedNodes ? bb::kEmitQuantizedNodes : 0u);
    const vk::ComputePipeline& pipeline = nodes(forms, !ordered);
    const vk::Binder nodeBinder = binder(pipeline);
    if (!ordered) {
      nodeBinder.bind(cmd, p);
      pipeline.dispatch(cmd, 1);
      vk::computeBarrier(cmd);
    }
    if (ordered) dispatchLevels(cmd, pipeline, nodeBinder, p, *a.schedule, 0, bb::kEmitMaxLevels);
  }
  vk::TimedScope scope(timer, cmd, "bvh_emit_leaves");
  binder(leaves_).bind(cmd, p);
  dispatchItems(leaves_, cmd, a.triangleCount);
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
