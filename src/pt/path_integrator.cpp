#include "pt/path_integrator.h"

#include "render/camera_frame.h"
#include "vk/timer.h"

namespace osr::pt {

const char* modeName(Mode mode) { return mode == Mode::Preview ? "preview" : "path"; }

std::optional<Mode> parseMode(const std::string& name) {
  if (name == "path") return Mode::Path;
  if (name == "preview") return Mode::Preview;
  return std::nullopt;
}

PathIntegrator::PathIntegrator(const vk::Context& ctx, const scene::GpuScene& scene,
                               const bvh::Bvh& bvh, uint32_t width, uint32_t height, Mode mode,
                               uint32_t pixelFilter)
    : ctx_(ctx),
      scene_(&scene),
      bvh_(&bvh),
      sceneFeatures_(scene.features),
      sceneTexelFetch_(scene.texelFetch),
      mode_(mode),
      pixelFilter_(pixelFilter),
      film_(ctx, width, height),
      frame_(ctx, sizeof(gpu::camera::CameraFrame), vk::MemoryUse::DeviceLocal, "pt frame"),
      pass_(ctx, mode, scene.features, scene.texelFetch) {
  pass_.prepare(bvh);
}

bool PathIntegrator::rebind(const scene::GpuScene& scene, const bvh::Bvh& bvh,
                            const scene::PoseChange& /*change*/) {
  if (scene.features != sceneFeatures_ || scene.texelFetch != sceneTexelFetch_) return false;
  scene_ = &scene;
  bvh_ = &bvh;
  pass_.prepare(bvh);  // a BVH of another node format needs its own pipeline
  return true;
}

void PathIntegrator::restart(const scene::Camera& camera, uint32_t seed) {
  const gpu::camera::CameraFrame f = render::makeFrame(camera, film_.width(), film_.height(), seed, pixelFilter_);
  frame_.upload(&f, sizeof f);
  ctx_.submitAndWait([&](VkCommandBuffer cmd) { film_.recordClear(cmd); });
}

void PathIntegrator::record(VkCommandBuffer cmd, uint32_t first, uint32_t count,
                            vk::GpuTimer* timer) {
  vk::TimedScope scope(timer, cmd, "pt_trace");
  pass_.record(cmd, {&film_, &frame_, bvh_, scene_, first, count});
}

void PathIntegrator::recordSlice(VkCommandBuffer cmd, uint32_t unit, uint32_t slice,
                                 uint32_t slices, vk::GpuTimer* timer) {
  vk::TimedScope scope(timer, cmd, "pt_trace");
  const uint64_t pixels = film_.pixelCount();
  const auto bound = [&](uint32_t s) { return uint32_t(pixels * s / slices); };
  pass_.record(cmd, {&film_, &frame_, bvh_, scene_, unit, 1, bound(slice),
                     bound(slice + 1) - bound(slice)});
}

void PathIntegrator::resolveInto(render::FilmLayers& into) const {
  film_.resolve(into);
  if (into.samples < 2) render::estimateVarianceFromNeighbours(into);
}

render::FilmLayers render(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
                          const scene::Camera& camera, const RenderSettings& settings,
                          const std::function<void(const render::Progress&)>& onProgress,
                          render::RenderStats* stats, const std::atomic<bool>* cancel) {
  PathIntegrator integrator(ctx, scene, bvh, settings.width, settings.height, settings.mode,
                            settings.pixelFilter);
  render::ProgressiveDriver driver(
      ctx, integrator,
      {settings.spp, settings.timeLimitS, settings.batchTargetS, settings.sliceUnits});
  driver.restart(camera, settings.seed);
  driver.run(onProgress, cancel);
  if (stats) *stats = driver.stats();
  return integrator.resolve();
}

}  // namespace osr::pt
