// Stage 4 of the GPU BVH build: treelet restructuring (Karras & Aila 2013) of the
// LBVH or PLOC tree.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/build_pass.h"

namespace osr::bvh {

// One round of treelet restructuring: bvh_treelet_count / _plan / _scatter, then bvh_treelet
// once per height with an indirect dispatch (see shared/bvh_build.h). Arrays: interior, leaves
// (bvh_treelet reads them through texels).
class TreeletPass {
 public:
  // treeletLeaves in 3..kTreeletMaxLeaves.
  TreeletPass(const vk::Context& ctx, uint32_t treeletLeaves, bool byAddress);
  static uint64_t scheduleBytes();
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange counters;
    const vk::Buffer* schedule = nullptr;  // scheduleBytes()
    vk::BufferRange nodeList;              // uint per interior node
    uint32_t triangleCount = 0;
    uint32_t minTriangles = 0;  // smallest subtree restructured
    // SubtreeCountPass's counts (uint per interior node) and their R32UI view: kept up to date
    // where countNodes (they are complete before the round: after PlocPass), else unread.
    vk::BufferRange subtreeNodes;
    VkBufferView subtreeNodeTexels = VK_NULL_HANDLE;
    bool countNodes = false;
  };
  // `timer` (may be null) gets scopes "bvh_treelet_schedule" (count, plan, scatter) and
  // "bvh_treelet" (the per-height dispatches).
  void record(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer = nullptr) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline count_, plan_, scatter_, treelet_;
};

}  // namespace osr::bvh
