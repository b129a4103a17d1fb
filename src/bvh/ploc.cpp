#include "bvh/ploc.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "bvh/build_pass.h"
#include "common/error.h"

namespace osr::bvh {

using namespace detail;

namespace {
std::vector<VkDescriptorType> plocTypes() {
  std::vector<VkDescriptorType> t =
      wordTexelTypes(bb::kPlocBindingCount, bb::kPlocBindingTexels, bb::kPlocBindingClusterTexels);
  for (uint32_t slot : {bb::kPlocBindingNearestTexels, bb::kPlocBindingSubtreeNodes + 1,
                        bb::kPlocBindingClusterTexels1})
    t[slot] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}
std::vector<vk::SpecConstant> plocSpec(const vk::Context& ctx) {
  return texelSpec(ctx, false, arraySpec(false));
}
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
vk::Binder PlocPass::binder(const vk::ComputePipeline& pipeline, const Args& a, uint32_t in,
                            uint32_t out, uint32_t parity, BuildPush& push) const {
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
      .set(bb::kPlocBindingTailClusters,
           a.tailClusters != 0 ? a.tailScratch : a.pairs)  // unread without a tail
      .setTexel(bb::kPlocBindingClusterTexels1, a.clusterTexels[1]);
  bindTexels(b, bb::kPlocBindingTexels, *a.texels);
  return b;
}

void PlocPass::record(VkCommandBuffer cmd, const Args& a, uint32_t iterations,
                      vk::GpuTimer* timer) const {
  if (a.triangleCount < 2 || groups(a.triangleCount) > bb::kMaxGroupsX)
    throw DeviceError("bvh: PLOC builds 2 to " +
                      std::to_string(uint64_t(bb::kMaxGroupsX) * bb::kWorkgroupSize) +
                      " triangles, not " + std::to_string(a.triangleCount));
  if (a.tailClusters != 0 && (a.tailCapacity > bb::kPlocTailCapacity ||
                              a.tailCapacity < std::min(a.tailClusters, a.triangleCount) ||
                              a.tailScratch.bytes() < 64ull * a.tailCapacity))
    throw DeviceError("bvh: PLOC's tail takes " + std::to_string(a.tailClusters) +
                      " clusters, but has room for " + std::to_string(a.tailCapacity));
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

PlocPass::Result PlocPass::result(const Args& a, uint32_t iterations) {
  const bb::PlocState state = a.state->downloadVector<bb::PlocState>(1)[0];
  return {state.count[finalParity(a.localRounds, iterations)], state.iterations};
}

// The global iterations alone stayed under 16 + 4 log2(n) on every mesh measured (docs/bvh.md,
// PLOC). With the tail they need only reach tailClusters, and the clusters left fall by a
// roughly constant factor per iteration: 2 + 4 ln(n / tailClusters) leaves room for meshes that
// merge more slowly.
PlocPass::Iterations::Iterations(uint32_t triangleCount, uint32_t tailClusters)
    : triangleCount_(triangleCount) {
  const uint32_t n = triangleCount;
  uint32_t log2n = 0;
  while ((uint64_t(1) << log2n) < n) ++log2n;
  count_ = std::min<uint32_t>(16 + 4 * log2n, n);
  if (tailClusters != 0)
    count_ = std::min<uint32_t>(
        2 + uint32_t(std::ceil(4.0 * std::log(std::max(1.0, double(n) / tailClusters)))), n);
}

bool PlocPass::Iterations::complete(uint32_t clustersLeft) {
  if (clustersLeft == 1) return true;
  if (count_ >= triangleCount_)
    throw DeviceError("bvh: PLOC left " + std::to_string(clustersLeft) + " clusters after " +
                      std::to_string(count_) + " iterations");
  count_ = std::min(2 * count_, triangleCount_);
  return false;
}

void PlocPass::recordLocal(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  if (a.localRounds == 0) return;
  if (!local_)
    throw DeviceError(
        "bvh: PLOC's local merges need subgroup shuffles, votes and ballots in subgroups of a "
        "multiple of " +
        std::to_string(bb::kPlocLocalChunk));
  vk::TimedScope scope(timer, cmd, "bvh_ploc_local");
  for (uint32_t k = 0; k < a.localRounds; ++k) {
    const uint32_t parity = k & 1u;
    BuildPush p{};
    binder(*local_, a, parity, parity ^ 1u, parity, p).bind(cmd, p);
    local_->dispatchIndirect(cmd, *a.state,
                             offsetof(bb::PlocState, args0) + parity * sizeof(bb::DispatchArgs));
    vk::computeBarrier(cmd);
  }
}

void PlocPass::recordIterations(VkCommandBuffer cmd, const Args& a, uint32_t iterations,
                                vk::GpuTimer* timer) const {
  vk::TimedScope scope(timer, cmd, "bvh_ploc");
  static_assert(offsetof(bb::PlocState, args1) ==
                offsetof(bb::PlocState, args0) + sizeof(bb::DispatchArgs));
  const uint64_t argsOffset = offsetof(bb::PlocState, args0);
  for (uint32_t k = 0; k < iterations; ++k) {
    const uint32_t parity =
        (a.localRounds + k) & 1u;  // reads clusters[parity], compacts into the other
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

}  // namespace osr::bvh
