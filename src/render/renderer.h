// The progressive render loop: samples are added to the film in batches (one submission per
// batch, dispatches of a few samples over chunks of pixels) until the sample count or the time
// budget runs out, whichever comes first. The same seed gives the same image.
#pragma once
#include <functional>
#include <string>

#include "bvh/bvh.h"
#include "render/film.h"
#include "scene/gpu_scene.h"
#include "scene/scene.h"

namespace osr::render {

struct RenderSettings {
  uint32_t width = 512;
  uint32_t height = 512;
  uint32_t spp = 64;        // upper bound on samples per pixel
  double timeLimitS = 0.0;  // 0: no limit; otherwise stop starting batches past it
  uint32_t seed = 0;
  uint32_t integrator = 0;     // gpu::pt::kIntegratorPath or kIntegratorPreview
  double batchTargetS = 0.25;  // aim for submissions this long (progress, time limit)
};

struct Progress {
  uint32_t samples = 0;
  uint32_t targetSamples = 0;
  double elapsedS = 0.0;
  double remainingS = 0.0;  // estimate
};

struct RenderStats {
  uint32_t samples = 0;
  double seconds = 0.0;  // wall time of the sample loop (excludes setup and resolve)
  double gpuMs = 0.0;    // GPU timestamps around the pt_trace dispatches (0 without timestamps)
};

// Renders `camera`'s view of the uploaded scene. onProgress (optional) is called after each
// batch.
FilmLayers render(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
                  const scene::Camera& camera, const RenderSettings& settings,
                  const std::function<void(const Progress&)>& onProgress = {},
                  RenderStats* stats = nullptr);

}  // namespace osr::render
