#include "bvh/treelet.h"

#include <optional>
#include <string>

#include "bvh/build_pass.h"
#include "common/error.h"

namespace osr::bvh {

using namespace detail;

namespace {
std::vector<VkDescriptorType> treeletTypes() {
  return wordTexelTypes(bb::kTreeletBindingCount, bb::kTreeletBindingTexels,
                        bb::kTreeletBindingSubtreeNodes + 1);
}
}  // namespace

TreeletPass::TreeletPass(const vk::Context& ctx, uint32_t treeletLeaves, bool byAddress)
    : access_{&ctx, byAddress},
      count_(ctx, shaders::Id::bvh_treelet_count, treeletTypes(), sizeof(BuildPush),
             texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, 0))),
      plan_(ctx, shaders::Id::bvh_treelet_plan, treeletTypes(), sizeof(BuildPush),
            climbSpec(ctx, byAddress, 0)),
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

}  // namespace osr::bvh
