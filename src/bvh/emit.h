// Stage 6 of the GPU BVH build: the traversal nodes in depth-first order and the leaf triangles.
#pragma once
#include <vulkan/vulkan.h>

#include <optional>

#include "bvh/build_pass.h"

namespace osr::bvh {

// bvh_emit_nodes once per depth (indirect), then bvh_emit_leaves: traversal nodes in depth-first
// order, then leaf triangles (info.leafCounter must be 0). Arrays: interior, leaves, prims (in,
// through texels), nodes, traversalNodes, leafTriangles (out).
class EmitPass {
 public:
  EmitPass(const vk::Context& ctx, bool byAddress);
  static uint64_t scheduleBytes();
  // Usage the slots buffer needs on top of storage use (its R32UI view, slotTexels).
  static constexpr VkBufferUsageFlags kSlotsUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange info;
    vk::BufferRange slots;                     // scratch: uint per interior node
    VkBufferView slotTexels = VK_NULL_HANDLE;  // R32UI view of slots (vk::BufferView::uintWords)
    // Depth-first order (unread for one triangle): SubtreeCountPass's counts; scratch positions,
    // node lists and leaf bases (uint per interior node) and the depth schedule (scheduleBytes()).
    vk::BufferRange subtreeNodes, positions, levelNodes, leafBases;
    const vk::Buffer* schedule = nullptr;
    uint32_t triangleCount = 0;
    bool exactNodes = true, quantizedNodes = true;  // which node arrays to write (Bvh::has*Nodes)
  };
  // `timer` (may be null) gets scopes "bvh_emit_nodes" (all depths) and "bvh_emit_leaves".
  void record(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer = nullptr) const;

 private:
  // bvh_emit_nodes specialized for (forms, one triangle) (shared/bvh_build.h, kEmitSpecForms),
  // made on first need: index forms | single << 2.
  const vk::ComputePipeline& nodes(uint32_t forms, bool singleTriangle) const;
  ArrayAccess access_;
  mutable std::optional<vk::ComputePipeline> nodes_[8];
  vk::ComputePipeline leaves_;
};

}  // namespace osr::bvh
