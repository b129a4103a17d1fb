// The pipeline of one OSR compute pass (a shaders/osr_*.comp) on the shared OSR binding layout,
// specialised on the scene's features, and how its invocations cover the work: one per pixel,
// one per map texel, or one per map, in windows of the buffers that can be larger than one
// binding. The pass classes (osr_passes.h) own one each and fill their own push constants.
#pragma once
#include <glm/glm.hpp>
#include <vector>

#include "bvh/traversal_pipeline.h"
#include "osr/osr_buffers.h"
#include "shaders/shared/osr.h"
#include "vk/binder.h"
#include "vk/pipeline.h"

namespace osr::oneshot {

// What one invocation of a pass covers: a pixel, a map texel, a map; MapGroups: a map per
// workgroup of kOsrWorkgroupSize invocations.
enum class Domain { Pixels, MapTexels, Maps, MapGroups };

class OsrPass {
 public:
  // pushBytes: the size of the pass's push struct (shared/osr.h).
  OsrPass(const vk::Context& ctx, shaders::Id shader, Domain domain, size_t pushBytes,
          uint32_t sceneFeatures, bool sceneTexelFetch, std::vector<vk::SpecConstant> extraSpec = {});

  const char* name() const { return pipeline_.name(); }
  // Makes the pipeline for `bvh`'s node format now (record would on first use, inside a render's
  // timed work): integrators call it when they are made.
  void prepare(const bvh::Bvh& bvh) const { pipeline_.forBvh(bvh); }

  // Pixel domain: dispatches over pixels [begin, end) (begin a multiple of
  // render::kWindowAlignPixels), at most kMaxPixelsPerDispatch each, each with the window of
  // clean maps its pixels read under `grid` (the 3 x 3 cells around each). Throws DeviceError
  // where even one grid cell row cannot be bound.
  std::vector<OsrWindow> pixelWindows(const OsrBindings& bindings, const gpu::osr::MapGrid& grid,
                                      uint32_t begin, uint32_t end) const;
  // Map domains: dispatches over maps [first, first + count) of one chunk; osr_maps (MapTexels)
  // also binds the G-buffer rows of its maps' grid cells (all of it for a grid of radius 0).
  std::vector<OsrWindow> mapWindows(const OsrBindings& bindings, const gpu::osr::MapGrid& grid,
                                    uint32_t first, uint32_t count) const;

  // One dispatch per window, with pushOf(window) (the pass's push struct) as push constants,
  // then a barrier.
  template <class Push, class PushOf>
  void record(VkCommandBuffer cmd, const OsrBindings& bindings,
              const std::vector<OsrWindow>& windows, PushOf pushOf) const {
    const vk::ComputePipeline& pipeline = pipeline_.forBvh(*bindings.bvh);
    vk::Binder binder(pipeline);
    for (const OsrWindow& w : windows) {
      const Push push = pushOf(w);
      bindings.fill(binder, w);
      binder.bind(cmd, push);
      const glm::uvec2 groups = groupsOf(w);
      pipeline.dispatch(cmd, groups.x, groups.y);
    }
    vk::computeBarrier(cmd);
  }

  static constexpr uint32_t kMaxPixelsPerDispatch = 1u << 20;

 private:
  glm::uvec2 groupsOf(const OsrWindow& w) const;

  Domain domain_;
  bvh::TraversalPipeline pipeline_;
  uint32_t pixelWindow_;  // most pixels of the per-pixel buffers one binding covers
  uint32_t mapWindow_;    // most clean maps one binding covers
};

// Pixels [begin, end) of the image; begin a multiple of render::kWindowAlignPixels.
struct PixelRange {
  uint32_t begin = 0, end = 0;
};
// Maps [first, first + count) of the current grid: one chunk of the map passes.
struct MapChunk {
  uint32_t first = 0, count = 0;
};

// The base of each pass class (osr_passes.h): its pipeline, made for push constants `Push`,
// and the recording over pixels or maps with a push struct the pass fills per window.
template <class Push>
class PassWithPush {
 public:
  void prepare(const bvh::Bvh& bvh) const { pass_.prepare(bvh); }

 protected:
  PassWithPush(const vk::Context& ctx, shaders::Id shader, Domain domain, uint32_t sceneFeatures,
               bool sceneTexelFetch, std::vector<vk::SpecConstant> extraSpec = {})
      : pass_(ctx, shader, domain, sizeof(Push), sceneFeatures, sceneTexelFetch,
              std::move(extraSpec)) {}
  // grid: the current maps' (the clean maps the pixels read), or {} for passes that read none.
  template <class PushOf>
  void recordPixels(VkCommandBuffer cmd, const OsrBindings& b, const gpu::osr::MapGrid& grid,
                    PixelRange pixels, PushOf pushOf) const {
    pass_.record<Push>(cmd, b, pass_.pixelWindows(b, grid, pixels.begin, pixels.end), pushOf);
  }
  template <class PushOf>
  void recordMaps(VkCommandBuffer cmd, const OsrBindings& b, const gpu::osr::MapGrid& grid,
                  MapChunk maps, PushOf pushOf) const {
    pass_.record<Push>(cmd, b, pass_.mapWindows(b, grid, maps.first, maps.count), pushOf);
  }

 private:
  OsrPass pass_;
};

}  // namespace osr::oneshot
