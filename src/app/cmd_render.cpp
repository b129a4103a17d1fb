// osr-vk [options] scene.gltf: loads the scene, builds the BVH, renders progressively with
// the chosen integrator and writes the multi-layer OpenEXR (--offline) and a PNG preview.
// Output paths are checked before any work, and files are written through a temporary name,
// so a failed render leaves existing files untouched.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "app/args.h"
#include "app/device_options.h"
#include "app/commands.h"
#include "app/image_io.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "osr/osr_integrator.h"
#include "render/renderer.h"
#include "scene/gpu_scene.h"
#include "scene/scene.h"
#include "shaders/shared/pt.h"
#include "vk/context.h"
#include "vk/timer.h"

namespace osr::app {

namespace {

LayeredImage toLayers(const render::FilmLayers& f) {
  LayeredImage img;
  img.width = f.width;
  img.height = f.height;
  const std::vector<std::string> rgb = {"R", "G", "B"}, xyz = {"X", "Y", "Z"};
  img.layers = {{"", rgb, f.combined},     {"direct", rgb, f.direct}, {"indirect", rgb, f.indirect},
                {"albedo", rgb, f.albedo}, {"normal", xyz, f.normal}, {"depth", {"Z"}, f.depth}};
  return img;
}

// One progress line on stderr: rewritten in place on a terminal, else at most every 5 s.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(bool quiet) : quiet_(quiet), tty_(::isatty(2)) {}
  void operator()(const render::Progress& p) {
    if (quiet_) return;
    bool last = p.samples >= p.targetSamples || p.remainingS <= 0.0;
    if (!tty_ && !last && p.elapsedS - lastPrinted_ < 5.0) return;
    lastPrinted_ = p.elapsedS;
    std::fprintf(stderr, "%sosr-vk: %u/%u spp, %.1f s elapsed, ~%.1f s remaining%s",
                 tty_ ? "\r" : "", p.samples, p.targetSamples, p.elapsedS, p.remainingS,
                 tty_ ? "   " : "\n");
    std::fflush(stderr);
    printed_ = true;
  }
  void finish() {
    if (printed_ && tty_) std::fputc('\n', stderr);
  }

 private:
  bool quiet_, tty_;
  bool printed_ = false;
  double lastPrinted_ = -1e9;
};

}  // namespace

int runRender(const std::vector<std::string>& args) {
  Args a(args, "render");
  std::string mode = a.value("--mode").value_or("path");
  auto exrPath = a.value("--offline");
  auto pngPath = a.value("--png");
  auto exposure = a.number("--exposure", -64, 64);
  auto width = a.integer("--width", 1, 16384);
  auto height = a.integer("--height", 1, 16384);
  auto spp = a.integer("--spp", 1, 1 << 24);
  auto timeLimit = a.number("--time", 0.001, 1e7);
  auto seed = a.integer("--seed", 0, 0xffffffffll);
  std::string cameraSelector = a.value("--camera").value_or("");
  auto envPath = a.value("--env");
  bool exrFloat = a.flag("--exr-float");
  bool quiet = a.flag("--quiet");
  auto passes = a.integer("--passes", 1, 1 << 24);
  auto denoiser = a.value("--denoiser");
  auto weights = a.value("--weights");
  auto gridStart = a.integer("--grid-start", 1, 256);
  auto gridMin = a.integer("--grid-min", 1, 256);
  auto directSpp = a.integer("--direct-spp", 1, 1024);
  auto residualSpp = a.integer("--residual-spp", 0, 1024);
  auto residualRamp = a.number("--residual-ramp", 0.0, 1e9);
  auto mapSpp = a.integer("--map-spp", 1, 1 << 16);
  vk::ContextOptions vkOptions = readDeviceOptions(a);
  auto files = a.positional();
  a.finish();
  if (files.size() != 1) throw InputError("render: expected exactly one scene file");
  uint32_t integrator = 0;
  const bool osrMode = mode == "osr";
  if (osrMode) {
  } else if (mode == "path")
    integrator = gpu::pt::kIntegratorPath;
  else if (mode == "preview")
    integrator = gpu::pt::kIntegratorPreview;
  else
    throw InputError("--mode: unknown integrator '" + mode + "' (osr, path, preview)");
  oneshot::OsrSettings osrSettings;
  if (denoiser) osrSettings.denoiser = oneshot::parseDenoiser(*denoiser);
  if (weights) {
    osrSettings.weightsPath = *weights;
    if (!denoiser) osrSettings.denoiser = oneshot::Denoiser::Unet;
  }
  if (gridStart) osrSettings.gridStart = uint32_t(*gridStart);
  if (gridMin) osrSettings.gridMin = uint32_t(*gridMin);
  if (directSpp) osrSettings.directSamples = uint32_t(*directSpp);
  if (residualSpp) osrSettings.residualSamples = uint32_t(*residualSpp);
  if (residualRamp) osrSettings.residualRamp = *residualRamp;
  if (mapSpp) osrSettings.pathsPerTexel = uint32_t(*mapSpp);
  if (osrSettings.gridMin > osrSettings.gridStart)
    throw InputError("--grid-min: " + std::to_string(osrSettings.gridMin) +
                     " is coarser than --grid-start " + std::to_string(osrSettings.gridStart));
  if (!exrPath && !pngPath)
    throw InputError("render: give --offline out.exr and/or --png out.png (no live viewer yet)");
  // Fail before the (long) render, not after it.
  if (exrPath) checkWritable(*exrPath);
  if (pngPath) checkWritable(*pngPath);

  scene::Scene sc = scene::loadScene(files[0]);
  std::optional<scene::Environment> env;
  if (envPath) env = scene::loadEnvironment(*envPath);
  float requestedAspect = width && height ? float(*width) / float(*height) : 0.f;
  scene::Camera camera = scene::selectCamera(sc, cameraSelector, requestedAspect);
  float aspect = camera.aspect > 0.f ? camera.aspect : 1.f;
  render::RenderSettings rs;
  if (width && height) {
    rs.width = uint32_t(*width);
    rs.height = uint32_t(*height);
  } else if (height) {
    rs.height = uint32_t(*height);
    rs.width = std::max(1u, uint32_t(std::lround(*height * aspect)));
  } else {
    rs.width = width ? uint32_t(*width) : 512u;
    rs.height = std::max(1u, uint32_t(std::lround(rs.width / aspect)));
  }
  // Preview is deterministic after one sample per pixel but antialiases with more.
  rs.spp = spp ? uint32_t(*spp) : (integrator == gpu::pt::kIntegratorPreview ? 4u : 64u);
  if (timeLimit) {
    rs.timeLimitS = *timeLimit;
    if (!spp) rs.spp = 1u << 24;  // --time alone: as many samples as fit
  }
  rs.seed = seed ? uint32_t(*seed) : 0u;
  rs.integrator = integrator;

  vk::Context ctx(vkOptions);
  scene::GpuScene gpuScene(ctx, sc, env ? &*env : nullptr);
  bvh::Bvh tree = bvh::buildGpu(ctx, gpuScene.vertices, gpuScene.triangles, gpuScene.triangleCount);
  ProgressPrinter progress(quiet);
  render::RenderStats stats;
  render::FilmLayers film;
  if (osrMode) {
    // TEMPORARY until the progressive driver lands: passes until --passes or --time.
    oneshot::OsrIntegrator osr(ctx, gpuScene, tree, rs.width, rs.height, osrSettings);
    osr.restart(camera, rs.seed);
    vk::GpuTimer timer(ctx, 256);
    const uint32_t maxPasses = passes ? uint32_t(*passes) : (timeLimit ? 1u << 24 : 16u);
    auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    uint32_t k = 0;
    double last = 0.0;
    while (k < maxPasses) {
      double now = elapsed();
      if (timeLimit && k > 0 && now + 0.5 * last >= *timeLimit) break;
      ctx.submitAndWait([&](VkCommandBuffer cmd) {
        timer.reset(cmd);
        osr.record(cmd, k, 1, &timer);
      });
      last = elapsed() - now;
      if (std::getenv("OSR_TIMINGS")) {
        std::fprintf(stderr, "pass %u:", k);
        for (auto& t : timer.results()) std::fprintf(stderr, " %s=%.1f", t.name.c_str(), t.ms);
        std::fprintf(stderr, " wall=%.1f ms\n", last * 1e3);
      }
      ++k;
    }
    stats.samples = k;
    stats.seconds = elapsed();
    film = osr.resolve();
  } else {
    film = render::render(ctx, gpuScene, tree, camera, rs,
                          [&](const render::Progress& p) { progress(p); }, &stats);
  }
  progress.finish();
  if (film.droppedSamples > 0)
    std::fprintf(stderr, "osr-vk: warning: %llu non-finite samples dropped\n",
                 static_cast<unsigned long long>(film.droppedSamples));
  if (exrPath)
    writeExr(*exrPath, toLayers(film), exrFloat ? ExrPixelType::Float : ExrPixelType::Half);
  if (pngPath) writePng(*pngPath, {film.width, film.height, film.combined}, exposure);
  if (!quiet)
    std::fprintf(
        stderr, "osr-vk: %ux%u, %u spp in %.2f s (%.3g Mpaths/s)\n", rs.width, rs.height,
        stats.samples, stats.seconds,
        double(rs.width) * rs.height * stats.samples / std::max(stats.seconds, 1e-9) * 1e-6);
  return 0;
}

}  // namespace osr::app
