// One OSR compute pass (a shaders/osr_*.comp): its pipeline on the shared OSR binding layout,
// specialised on the scene's features, and how its invocations cover the work: one per pixel,
// one per map texel, or one per map. The passes differ only in shader and domain, so one class
// serves them all; the integrator (osr_integrator.cpp) names and orders them.
#pragma once
#include <vector>

#include "bvh/traversal_pipeline.h"
#include "osr/osr_buffers.h"
#include "shaders/shared/osr.h"
#include "vk/pipeline.h"

namespace osr::oneshot {

enum class Domain { Pixels, MapTexels, Maps };

class OsrPass {
 public:
  OsrPass(const vk::Context& ctx, shaders::Id shader, Domain domain, uint32_t sceneFeatures,
          bool sceneTexelFetch, std::vector<vk::SpecConstant> extraSpec = {});

  const char* name() const { return pipeline_.name(); }
  // Makes the pipeline for `bvh`'s node format now (record would on first use, inside a render's
  // timed work): integrators call it when they are made.
  void prepare(const bvh::Bvh& bvh) const { pipeline_.forBvh(bvh); }

  // Records the pass over push.mapCount maps (map domains) or pixels [pixelBegin, pixelEnd)
  // (pixel domain, in dispatches of at most kMaxPixelsPerDispatch; pixelBegin a multiple of
  // render::kWindowAlignPixels), then a barrier. Each dispatch binds the
  // windows of the per-pixel and clean-map buffers it reads (shared/osr.h), so images larger
  // than one binding render; throws DeviceError where even one grid cell row cannot be bound.
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, gpu::osr::OsrPush push,
              uint32_t pixelEnd = 0, uint32_t pixelBegin = 0) const;

  static constexpr uint32_t kMaxPixelsPerDispatch = 1u << 20;

 private:
  Domain domain_;
  bvh::TraversalPipeline pipeline_;
  uint32_t pixelWindow_;  // most pixels of the per-pixel buffers one binding covers
  uint32_t mapWindow_;    // most clean maps one binding covers
};

}  // namespace osr::oneshot
