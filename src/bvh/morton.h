// Stage 2 of the GPU BVH build: Morton codes of the centroids, the keys of the sort.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/build_pass.h"

namespace osr::bvh {

// bvh_morton: keys = Morton codes of the centroids, values = triangle indices. Arrays: prims
// (through texels).
class MortonPass {
 public:
  MortonPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange info, keys, values;
    uint32_t triangleCount = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::bvh
