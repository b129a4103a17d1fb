// Stage 1 of the GPU BVH build: vertex copies per triangle and the centroid bounds.
#pragma once
#include <vulkan/vulkan.h>

#include <optional>

#include "bvh/build_pass.h"

namespace osr::bvh {

// bvh_bounds: vertex copies per triangle + centroid bounds (info must hold the empty box).
// Arrays: triangles, vertices (in), prims (out).
class BoundsPass {
 public:
  BoundsPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    vk::BufferRange info;  // in/out: BvhBuildInfo
    uint32_t triangleCount = 0;
    // RGBA32UI views of the scene's triangles and vertices (vk::BufferView::uintTexels) that
    // reach every triangle and vertex, or null: then the pass reads the storage arrays.
    VkBufferView triangleTexels = VK_NULL_HANDLE, vertexTexels = VK_NULL_HANDLE;
    VkBufferView unusedTexels = VK_NULL_HANDLE;  // any valid view, bound in their place when null
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  mutable std::optional<vk::ComputePipeline>
      pipelines_[2];  // by kBoundsSpecSceneTexels, made on first need
};

}  // namespace osr::bvh
