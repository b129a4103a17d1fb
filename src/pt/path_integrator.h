// The path tracer and its preview as an Integrator (render/integrator.h): one unit is one
// sample per pixel, recorded by TracePass into the film. Also pt::render(), the whole loop
// (integrator + progressive driver) for callers that want one image.
#pragma once
#include <functional>
#include <optional>
#include <string>

#include "bvh/bvh.h"
#include "pt/trace_pass.h"
#include "render/film.h"
#include "shaders/shared/camera.h"
#include "render/integrator.h"
#include "render/progressive_driver.h"
#include "scene_gpu/gpu_scene.h"
#include "vk/buffer.h"

namespace osr::pt {

// "path" / "preview", as --mode spells them.
const char* modeName(Mode mode);
std::optional<Mode> parseMode(const std::string& name);

class PathIntegrator : public render::Integrator {
 public:
  // scene and bvh must outlive the integrator. width, height >= 1; pixelFilter:
  // gpu::camera::kPixelFilter*.
  PathIntegrator(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
                 uint32_t width, uint32_t height, Mode mode,
                 uint32_t pixelFilter = gpu::camera::kPixelFilterBlackmanHarris);

  const char* name() const override { return modeName(mode_); }
  const char* unitName() const override { return "spp"; }
  uint32_t maxUnitsPerSubmission() const override { return kMaxSamplesPerSubmission; }
  // A scene rebuilt with the same features and texel reads (a shot's frame that moved meshes
  // or lights): the pipelines, film and camera buffer carry over, which saves their making
  // (about 2 s on lavapipe) every such frame; a path tracer keeps no other state.
  bool rebind(const scene::GpuScene& scene, const bvh::Bvh& bvh,
              const scene::PoseChange& change) override;
  void restart(const scene::Camera& camera, uint32_t seed) override;
  // Opens timer scope "pt_trace".
  void record(VkCommandBuffer cmd, uint32_t first, uint32_t count, vk::GpuTimer* timer) override;
  // A slice is a band of whole rows' worth of pixels (row-major), one sample each.
  uint32_t maxSlicesPerUnit() const override { return kMaxSlicesPerUnit; }
  void recordSlice(VkCommandBuffer cmd, uint32_t unit, uint32_t slice, uint32_t slices,
                   vk::GpuTimer* timer) override;
  const render::Film& film() const override { return film_; }
  // The film's layers; with one sample per pixel, each pixel's variance from its neighbours
  // (render::estimateVarianceFromNeighbours), so the denoisers filter the first image too.
  void resolveInto(render::FilmLayers& into) const override;

  static constexpr uint32_t kMaxSamplesPerSubmission = 1024;
  static constexpr uint32_t kMaxSlicesPerUnit = 256;

 private:
  const vk::Context& ctx_;
  const scene::GpuScene* scene_;  // rebind() replaces them
  const bvh::Bvh* bvh_;
  // What the pipelines were made for (the scene may be gone when rebind() is called).
  uint32_t sceneFeatures_;
  bool sceneTexelFetch_;
  Mode mode_;
  uint32_t pixelFilter_;
  render::Film film_;
  vk::Buffer frame_;  // gpu::camera::CameraFrame
  TracePass pass_;
};

struct RenderSettings {
  uint32_t width = 512;
  uint32_t height = 512;
  uint32_t spp = 64;        // upper bound on samples per pixel
  double timeLimitS = 0.0;  // 0: no limit; otherwise stop starting batches past it
  uint32_t seed = 0;
  Mode mode = Mode::Path;
  double batchTargetS = 0.25;  // aim for submissions this long (progress, time limit)
  bool sliceUnits = false;     // split samples into pixel bands (render::DriverSettings)
  uint32_t pixelFilter = gpu::camera::kPixelFilterBlackmanHarris;  // kPixelFilter*
};

// Renders `camera`'s view of the uploaded scene with a PathIntegrator under a
// ProgressiveDriver. onProgress (optional) is called after each submission; cancel (optional)
// is checked between submissions.
render::FilmLayers render(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
                          const scene::Camera& camera, const RenderSettings& settings,
                          const std::function<void(const render::Progress&)>& onProgress = {},
                          render::RenderStats* stats = nullptr,
                          const std::atomic<bool>* cancel = nullptr);

}  // namespace osr::pt
