// osr-vk [options] scene.gltf: loads the scene, builds the BVH, renders progressively with
// the chosen integrator and writes the multi-layer OpenEXR (--offline) and a PNG preview.
// Output paths are checked before any work, and files are written through a temporary name,
// so a failed render leaves existing files untouched.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include "app/args.h"
#include "app/device_options.h"
#include "app/commands.h"
#include "image/image_io.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "pt/path_integrator.h"
#include "scene_gpu/gpu_scene.h"
#include "scene/scene.h"
#include "vk/context.h"

namespace osr::app {

namespace {

image::LayeredImage toLayers(const render::FilmLayers& f) {
  image::LayeredImage img;
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
    bool last = p.units >= p.targetUnits || p.remainingS <= 0.0;
    if (!tty_ && !last && p.elapsedS - lastPrinted_ < 5.0) return;
    lastPrinted_ = p.elapsedS;
    std::fprintf(stderr, "%sosr-vk: %u/%u %s, %.1f s elapsed, ~%.1f s remaining%s",
                 tty_ ? "\r" : "", p.units, p.targetUnits, p.unitName, p.elapsedS, p.remainingS,
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
  vk::ContextOptions vkOptions = readDeviceOptions(a);
  auto files = a.positional();
  a.finish();
  if (files.size() != 1) throw InputError("render: expected exactly one scene file");
  std::optional<pt::Mode> integrator = pt::parseMode(mode);
  if (!integrator) throw InputError("--mode: unknown integrator '" + mode + "' (path, preview)");
  if (!exrPath && !pngPath)
    throw InputError("render: give --offline out.exr and/or --png out.png (no live viewer yet)");
  // Fail before the (long) render, not after it.
  if (exrPath) image::checkWritable(*exrPath);
  if (pngPath) image::checkWritable(*pngPath);

  scene::Scene sc = scene::loadScene(files[0]);
  std::optional<scene::Environment> env;
  if (envPath) env = scene::loadEnvironment(*envPath);
  float requestedAspect = width && height ? float(*width) / float(*height) : 0.f;
  scene::Camera camera = scene::selectCamera(sc, cameraSelector, requestedAspect);
  float aspect = camera.aspect > 0.f ? camera.aspect : 1.f;
  pt::RenderSettings rs;
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
  rs.spp = spp ? uint32_t(*spp) : (*integrator == pt::Mode::Preview ? 4u : 64u);
  if (timeLimit) {
    rs.timeLimitS = *timeLimit;
    if (!spp) rs.spp = 1u << 24;  // --time alone: as many samples as fit
  }
  rs.seed = seed ? uint32_t(*seed) : 0u;
  rs.mode = *integrator;

  vk::Context ctx(vkOptions);
  scene::GpuScene gpuScene(ctx, sc, env ? &*env : nullptr);
  bvh::Bvh tree = bvh::buildGpu(ctx, gpuScene.vertices, gpuScene.triangles, gpuScene.triangleCount);
  ProgressPrinter progress(quiet);
  render::RenderStats stats;
  render::FilmLayers film = pt::render(
      ctx, gpuScene, tree, camera, rs, [&](const render::Progress& p) { progress(p); }, &stats);
  progress.finish();
  if (film.droppedSamples > 0)
    std::fprintf(stderr, "osr-vk: warning: %llu non-finite samples dropped\n",
                 static_cast<unsigned long long>(film.droppedSamples));
  if (exrPath)
    image::writeExr(*exrPath, toLayers(film), exrFloat ? image::ExrPixelType::Float : image::ExrPixelType::Half);
  if (pngPath) image::writePng(*pngPath, {film.width, film.height, film.combined}, exposure);
  if (!quiet)
    std::fprintf(
        stderr, "osr-vk: %ux%u, %u spp in %.2f s (%.3g Mpaths/s)\n", rs.width, rs.height,
        stats.units, stats.seconds,
        double(rs.width) * rs.height * stats.units / std::max(stats.seconds, 1e-9) * 1e-6);
  return 0;
}

}  // namespace osr::app
