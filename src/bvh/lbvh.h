// Stage 4 (LBVH hierarchy) of the GPU BVH build: the Karras tree over the sorted keys.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/build_pass.h"

namespace osr::bvh {

// bvh_lbvh: Karras 2012 hierarchy over sorted keys; initialises the leaves. Arrays: prims
// (in, through texels), interior, leaves (out).
class LbvhPass {
 public:
  LbvhPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange keys, values;
    VkBufferView keyTexels = VK_NULL_HANDLE;  // R32UI view of keys (vk::BufferView::uintWords)
    uint32_t triangleCount = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::bvh
