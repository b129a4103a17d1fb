// pt_trace.comp as a pass: one sample for a range of pixels, added to the film.
//
// Megakernel, not wavefront: on lavapipe (2 CPU threads, SIMD width 8) a wavefront split pays
// a dispatch and a full write/read of the path state per bounce, while the megakernel's path
// regeneration already keeps its lanes busy. A wavefront prototype with ray pools was slower
// per bounce on both reference scenes (docs/pathtracer.md, "Tried and not kept"). A GPU may
// prefer it; not measured there.
// Dispatches are one sample over at most kMaxPixelsPerDispatch pixels, short enough for a
// desktop GPU's watchdog.
#pragma once
#include "bvh/bvh.h"
#include "bvh/traversal_pipeline.h"
#include "render/film.h"
#include "scene_gpu/gpu_scene.h"
#include "shaders/shared/pt.h"
#include "vk/pipeline.h"

namespace osr::pt {

// What a sample computes.
enum class Mode {
  Path,     // unidirectional path tracing, NEE + MIS
  Preview,  // primary hit: albedo x headlight cosine
};

class TracePass {
 public:
  // sceneFeatures: the scene's kSceneFeature* bits (scene::GpuScene::features); code for absent
  // features is compiled out. sceneTexelFetch: read vertices, triangles, materials through the
  // scene's texel views (scene::GpuScene::texelFetch).
  TracePass(const vk::Context& ctx, Mode mode,
            uint32_t sceneFeatures = gpu::scene::kSceneFeatureAll, bool sceneTexelFetch = false);

  // A multiple of render::kWindowAlignPixels: dispatches start on film window boundaries.
  static constexpr uint32_t kMaxPixelsPerDispatch = 1u << 20;
  static constexpr uint32_t kMaxSamplesPerDispatch = 8;

  struct Args {
    const render::Film* film = nullptr;
    const vk::Buffer* frame = nullptr;  // gpu::camera::CameraFrame
    const bvh::Bvh* bvh = nullptr;
    const scene::GpuScene* scene = nullptr;
    uint32_t sampleIndex = 0;  // first sample
    uint32_t sampleCount = 1;
    // Pixels [pixelFirst, pixelFirst + pixelCount) in row-major order, clamped to the film
    // (a slice of the image, so the viewer's submissions stay short).
    uint32_t pixelFirst = 0;
    uint32_t pixelCount = ~0u;
  };
  // Records samples [sampleIndex, sampleIndex + sampleCount) for the pixel range, in
  // dispatches of bounded size, with barriers.
  void record(VkCommandBuffer cmd, const Args& args) const;
  // Makes the pipeline for `bvh`'s node format now (record would on first use, inside a render's
  // timed work): the integrator calls it when it is made.
  void prepare(const bvh::Bvh& bvh) const { pipeline_.forBvh(bvh); }

 private:
  bvh::TraversalPipeline pipeline_;
  uint32_t filmWindow_;  // most film pixels one binding covers (render::windowPixels)
};

}  // namespace osr::pt
