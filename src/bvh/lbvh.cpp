#include "bvh/lbvh.h"

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

LbvhPass::LbvhPass(const vk::Context& ctx, bool byAddress)
    : access_{&ctx, byAddress},
      pipeline_(
          ctx, shaders::Id::bvh_lbvh,
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

}  // namespace osr::bvh
