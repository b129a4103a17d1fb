// The batch tracer pass (shaders/bvh_trace_rays.comp): one closest-hit or any-hit query per
// ray of a buffer. The alpha variant (bvh_trace_rays_alpha.comp) takes a per-triangle test mask
// and exists for the tests of OSR_BVH_ALPHA_TEST.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/bvh.h"
#include "bvh/traversal_pipeline.h"
#include "shaders/shared/bvh_trace.h"
#include "vk/pipeline.h"

namespace osr::bvh {

class TraceRaysPass {
 public:
  TraceRaysPass(const vk::Context& ctx, bool alphaTest = false, Access access = Access::Auto);

  struct Args {
    const Bvh* bvh = nullptr;
    vk::BufferRange rays;       // TraceRay[rayCount]
    vk::BufferRange hits;       // TraceHit[rayCount]
    vk::BufferRange alphaMask;  // uint per triangle; alpha variant only
    uint32_t rayCount = 0;
    uint32_t mode = gpu::bvh_trace::kModeClosest;
    // Rays per invocation: each subgroup traces a pool of this many rays per lane, a lane taking
    // the next when its ray is done (shaders/lib/bvh_trace_rays_main.glsl). 1 = one ray per
    // invocation through bvhClosestHit / bvhAnyHit, as the renderers trace.
    uint32_t raysPerLane = 16;
  };
  // Records bind + dispatch + the barrier that makes the hits visible to later passes.
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  bool alphaTest_;
  bool storageAccess_;  // reads the BVH's storage bindings (traversalSpec chose storage)
  TraversalPipeline pooled_;  // ray pools (raysPerLane > 1)
  TraversalPipeline single_;  // one ray per invocation (raysPerLane 1)
};

}  // namespace osr::bvh
