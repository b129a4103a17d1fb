#include "bvh/refit.h"

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

RefitPass::RefitPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(ctx, shaders::Id::bvh_refit,
                texelTypes(bb::kRefitBindingCount, bb::kRefitBindingTexels), sizeof(BuildPush),
                texelSpec(ctx, byAddress, climbSpec(ctx, byAddress, 0))) {}

void RefitPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder binder(pipeline_);
  recordClimb(cmd, pipeline_, binder, access_, *a.arrays, *a.texels, bb::kRefitBindingTexels,
              *a.counters, a.triangleCount);
}

}  // namespace osr::bvh
