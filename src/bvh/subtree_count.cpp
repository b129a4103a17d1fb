#include "bvh/subtree_count.h"

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

SubtreeCountPass::SubtreeCountPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(ctx, shaders::Id::bvh_subtree_count,
                texelTypes(bb::kSubtreeCountBindingCount, bb::kSubtreeCountBindingTexels),
                sizeof(BuildPush), texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, 0))) {}

void SubtreeCountPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder binder(pipeline_);
  binder.set(bb::kSubtreeCountBindingNodes, a.subtreeNodes);
  recordClimb(cmd, pipeline_, binder, access_, *a.arrays, *a.texels, bb::kSubtreeCountBindingTexels,
              a.counters, a.triangleCount);
}

}  // namespace osr::bvh
