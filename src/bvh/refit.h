// Stage 4 (LBVH hierarchy) of the GPU BVH build: bounds and costs of the Karras tree,
// bottom up.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/build_pass.h"

namespace osr::bvh {

// bvh_refit: bottom-up bounds, counts, costs, heights; counters are zeroed by record().
// Arrays: interior, leaves (also through texels).
class RefitPass {
 public:
  RefitPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    const vk::Buffer* counters = nullptr;  // uint per interior node
    uint32_t triangleCount = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::bvh
