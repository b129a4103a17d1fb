// The pipeline of a pass that traverses the BVH, specialised for the node format of the BVH it
// is recorded with (Bvh::quantized, specialization constant kBvhSpecQuantized) and made on first
// need: a run compiles only the format its scene uses, and a pass can never read one format
// with the other's code.
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "bvh/bvh.h"
#include "vk/pipeline.h"

namespace osr::bvh {

class TraversalPipeline {
 public:
  // `spec`: the pass's own constants (traversalSpec included); the format's is added per use.
  TraversalPipeline(const vk::Context& ctx, shaders::Id shader, std::vector<VkDescriptorType> types,
                    uint32_t pushBytes, std::vector<vk::SpecConstant> spec);
  const vk::ComputePipeline& forBvh(const Bvh& bvh) const;
  const char* name() const { return shaders::module(shader_).name; }
  const vk::Context& context() const { return *ctx_; }

 private:
  const vk::Context* ctx_;
  shaders::Id shader_;
  std::vector<VkDescriptorType> types_;
  uint32_t pushBytes_;
  std::vector<vk::SpecConstant> spec_;
  mutable std::array<std::unique_ptr<vk::ComputePipeline>, 2> byFormat_;  // exact, quantized
};

}  // namespace osr::bvh
