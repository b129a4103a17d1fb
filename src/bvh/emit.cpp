#include "bvh/emit.h"

#include <optional>

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

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
    std::vector<vk::SpecConstant> spec =
        wordTexelSpec(*access_.ctx, access_.byAddress, bb::kEmitSpecSlotTexels);
    spec.push_back(vk::specUint(bb::kEmitSpecForms, forms));
    spec.push_back(vk::specUint(bb::kEmitSpecSingleTriangle, singleTriangle ? 1u : 0u));
    pipeline.emplace(*access_.ctx, shaders::Id::bvh_emit_nodes, emitTypes(), sizeof(BuildPush),
                     spec);
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
    static_assert(sizeof(Schedule) ==
                  bb::kEmitMaxLevels * (sizeof(bb::LevelList) + sizeof(bb::DispatchArgs)));
    for (bb::DispatchArgs& d : initial.args) d = {0, 1, 1};
    initial.levels[0].count = 1;
    initial.args[0].x = 1;
    vkCmdUpdateBuffer(cmd, a.schedule->handle(), 0, sizeof(initial), &initial);
    vkCmdFillBuffer(cmd, a.positions.buffer->handle(), a.positions.offset, 4,
                    0);  // the root's position
    vkCmdFillBuffer(cmd, a.levelNodes.buffer->handle(), a.levelNodes.offset, 4,
                    0);  // depth 0: the root
    vkCmdFillBuffer(cmd, a.leafBases.buffer->handle(), a.leafBases.offset, 4,
                    0);  // the root's leaf base
    vk::transferBarrier(cmd);
  }
  BuildPush p{};
  // The two pipelines bind the same buffers at the same slots.
  auto binder = [&](const vk::ComputePipeline& pipeline) {
    vk::Binder b(pipeline);
    p = bindArrays(b, access_, *a.arrays, a.triangleCount, 0);
    b.set(bb::kEmitBindingInfo, a.info)
        .set(bb::kEmitBindingSlots, a.slots)
        .setTexel(bb::kEmitBindingSlotTexels, a.slotTexels);
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
    const uint32_t forms = (a.exactNodes ? bb::kEmitExactNodes : 0u) |
                           (a.quantizedNodes ? bb::kEmitQuantizedNodes : 0u);
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
