#include "bvh/morton.h"

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

MortonPass::MortonPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(ctx, shaders::Id::bvh_morton,
                texelTypes(bb::kMortonBindingCount, bb::kMortonBindingTexels), sizeof(BuildPush),
                texelSpec(ctx, byAddress, arraySpec(byAddress))) {}

void MortonPass::record(VkCommandBuffer cmd, const Args& a) const {
  vk::Binder binder(pipeline_);
  BuildPush p = bindArrays(binder, access_, *a.arrays, a.triangleCount, 0);
  binder.set(bb::kMortonBindingInfo, a.info)
      .set(bb::kMortonBindingKeys, a.keys)
      .set(bb::kMortonBindingValues, a.values);
  bindTexels(binder, bb::kMortonBindingTexels, *a.texels);
  binder.bind(cmd, p);
  dispatchItems(pipeline_, cmd, a.triangleCount);
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
