#include "bvh/traversal_pipeline.h"

namespace osr::bvh {

TraversalPipeline::TraversalPipeline(const vk::Context& ctx, shaders::Id shader, std::vector<VkDescriptorType> types,
                                     uint32_t pushBytes, std::vector<vk::SpecConstant> spec)
    : ctx_(&ctx), shader_(shader), types_(std::move(types)), pushBytes_(pushBytes), spec_(std::move(spec)) {}

const vk::ComputePipeline& TraversalPipeline::forBvh(const Bvh& bvh) const {
  std::unique_ptr<vk::ComputePipeline>& p = byFormat_[bvh.quantized ? 1 : 0];
  if (!p) {
    std::vector<vk::SpecConstant> spec = spec_;
    spec.push_back(vk::specUint(gpu::bvh::kBvhSpecQuantized, bvh.quantized ? 1u : 0u));
    p = std::make_unique<vk::ComputePipeline>(*ctx_, shader_, types_, pushBytes_, spec);
  }
  return *p;
}

}  // namespace osr::bvh
