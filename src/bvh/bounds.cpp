#include "bvh/bounds.h"

#include <optional>

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

BoundsPass::BoundsPass(const vk::Context& ctx, bool byAddress) : access_{&ctx, byAddress} {}

void BoundsPass::record(VkCommandBuffer cmd, const Args& a) const {
  const bool sceneTexels = a.triangleTexels && a.vertexTexels;
  std::optional<vk::ComputePipeline>& pipeline = pipelines_[sceneTexels ? 1 : 0];
  if (!pipeline) {
    std::vector<vk::SpecConstant> spec = arraySpec(access_.byAddress);
    spec.push_back(vk::specUint(bb::kBoundsSpecSceneTexels, sceneTexels ? 1u : 0u));
    pipeline.emplace(
        *access_.ctx, shaders::Id::bvh_bounds,
        storageAndTexelTypes(bb::kBoundsBindingCount,
                             {bb::kBoundsBindingTriangleTexels, bb::kBoundsBindingVertexTexels}),
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

}  // namespace osr::bvh
