// Stage 5 of the GPU BVH build: subtree sizes for the depth-first layout of the emit.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/build_pass.h"

namespace osr::bvh {

// bvh_subtree_count: traversal nodes per subtree, for the depth-first order of bvh_emit_nodes.
// Arrays: interior, leaves (through texels).
class SubtreeCountPass {
 public:
  SubtreeCountPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange counters;      // scratch: uint per interior node (zeroed here)
    vk::BufferRange subtreeNodes;  // out: uint per interior node
    uint32_t triangleCount = 0;    // >= 2
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::bvh
