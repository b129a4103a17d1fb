// osr-vk [options] scene.gltf: loads the scene, builds the BVH, renders progressively with
// the chosen integrator and writes the multi-layer OpenEXR (--offline) and a PNG preview.
// Output paths are checked before any work, and files are written through a temporary name,
// so a failed render leaves existing files untouched.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "app/args.h"
#include "app/commands.h"
#include "app/denoise_options.h"
#include "app/device_options.h"
#include "app/frames.h"
#include "app/output_paths.h"
#include "app/scene_setup.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "image/image_io.h"
#include "osr/osr_integrator.h"
#include "pt/path_integrator.h"
#include "render/film_export.h"
#include "render/progressive_driver.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"
#include "viewer/viewer.h"
#include "viewer/window.h"
#include "vk/context.h"

namespace osr::app {

namespace {

// "1 pass", not "1 passes", where the count stands alone ("1/32 passes" reads "of 32").
const char* unitWord(const char* unitName, uint32_t count) {
  return count == 1 && std::string(unitName) == "passes" ? "pass" : unitName;
}

// One progress line on stderr: rewritten in place on a terminal, else at most every 5 s.
// Format (parsed by front ends; README "Progress"): "osr-vk: U/T UNIT, E s elapsed, ~R s
// remaining", where "/T" is left out when only --time bounds the render and " (+P% of the
// next)" follows UNIT while a unit runs in slices.
class ProgressPrinter {
 public:
  ProgressPrinter(bool quiet, bool unitBound) : quiet_(quiet), unitBound_(unitBound), tty_(::isatty(2)) {}
  void operator()(const render::Progress& p) {
    if (quiet_) return;
    // The final line; not each slice of a unit that runs past the time budget.
    bool last = p.units >= p.targetUnits || (p.remainingS <= 0.0 && p.unitFraction == 0.0);
    if (!tty_ && !last && p.elapsedS - lastPrinted_ < 5.0) return;
    lastPrinted_ = p.elapsedS;
    const std::string target = unitBound_ ? "/" + std::to_string(p.targetUnits) : "";
    // A unit in slices: how much of the next one is done, after the unit name.
    char partial[48] = "";
    if (p.unitFraction > 0.0)
      std::snprintf(partial, sizeof partial, " (+%.0f%% of the next)", 100.0 * p.unitFraction);
    std::fprintf(stderr, "%sosr-vk: %u%s %s%s, %.1f s elapsed, ~%.1f s remaining%s",
                 tty_ ? "\r" : "", p.units, target.c_str(),
                 unitBound_ ? p.unitName : unitWord(p.unitName, p.units), partial, p.elapsedS,
                 p.remainingS, tty_ ? "   " : "\n");
    std::fflush(stderr);
    printed_ = true;
  }
  void finish() {
    if (printed_ && tty_) std::fputc('\n', stderr);
  }

 private:
  bool quiet_, unitBound_, tty_;
  bool printed_ = false;
  double lastPrinted_ = -1e9;
};

// --dump-maps DIR (made before the render): the maps of the last map pass as atlases a person
// can look at (one tile per grid cell, in grid order, 1-texel gaps): oneshot.png (the traced
// input), clean.png (what the denoiser made of it; the raw map with --denoiser none), and
// grid.png, the image with the grid points marked in red.
void writeMapDump(const std::string& dir, const oneshot::OsrIntegrator::MapDump& d,
                  const render::FilmLayers& film) {
  const int tile = 33, w = int(d.cellsX) * tile, h = int(d.cellsY) * tile;
  auto atlas = [&](const std::vector<float>& maps, uint32_t channels) {
    image::RgbImage img{w, h, std::vector<float>(size_t(w) * h * 3, 0.f)};
    for (uint32_t m = 0; m < d.maps; ++m)
      for (uint32_t t = 0; t < 1024; ++t)
        for (int c = 0; c < 3; ++c) {
          int x = int(m % d.cellsX) * tile + int(t % 32),
              y = int(m / d.cellsX) * tile + int(t / 32);
          img.rgb[(size_t(y) * w + x) * 3 + c] = maps[(size_t(m) * channels + c) * 1024 + t];
        }
    return img;
  };
  if (!d.oneShot.empty()) image::writePng(dir + "/oneshot.png", atlas(d.oneShot, 7), {});
  image::writePng(dir + "/clean.png", atlas(d.clean, 3), {});
  image::RgbImage frame{film.width, film.height, film.combined};
  const double ev = image::autoExposureEv(frame, film.depth);  // metered before the markers
  for (const auto& r : d.points) {
    if (r.position.w < 0.5f) continue;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        int x = int(r.pixel.x) + dx, y = int(r.pixel.y) + dy;
        if (x < 0 || y < 0 || x >= film.width || y >= film.height) continue;
        float* p = &frame.rgb[(size_t(y) * film.width + x) * 3];
        p[0] = 1e6f, p[1] = 0.f, p[2] = 0.f;
      }
  }
  image::writePng(dir + "/grid.png", frame, ev);
}

}  // namespace

int runRender(const std::vector<std::string>& args) {
  Args a(args, "render");
  std::string mode = a.value("--mode").value_or("osr");
  auto exrPath = a.value("--offline");
  auto pngPath = a.value("--png");
  auto exposure = a.number("--exposure", -64, 64);
  auto spp = a.integer("--spp", 1, 1 << 24);
  auto timeLimit = a.number("--time", 0.001, 1e7);
  auto seed = a.integer("--seed", 0, 0xffffffffll);
  SceneOptions sceneOptions = readSceneOptions(a);
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
  auto mapShare = a.number("--map-share", 0.0, 1.0);
  auto dumpMaps = a.value("--dump-maps");
  auto viewerScript = a.value("--viewer-script");
  auto saveDir = a.value("--save-dir");
  auto crop = a.integerList("--crop", 0, 16384);
  const std::optional<FrameOptions> frames = readFrameOptions(a);
  const render::DenoiseSettings denoise = readDenoiseOptions(a, mode);
  denoise.check();  // a bad model: one line and exit 2 before any work
  vk::ContextOptions vkOptions = readDeviceOptions(a);
  auto files = a.positional();
  a.finish();
  if (files.size() != 1) throw InputError("render: expected exactly one scene file");
  const bool osrMode = mode == "osr";
  std::optional<pt::Mode> ptMode = pt::parseMode(mode);
  if (!osrMode && !ptMode)
    throw InputError("--mode: unknown integrator '" + mode + "' (osr, path, preview)");
  if (!osrMode && (passes || denoiser || weights || gridStart || gridMin || directSpp ||
                   residualSpp || residualRamp || mapSpp || mapShare))
    throw InputError(
        "render: --passes, --denoiser, --weights, --grid-*, --direct-spp, "
        "--residual-*, --map-spp are options of --mode osr");
  if (osrMode && spp)
    throw InputError("--spp: --mode osr counts progressive passes; use --passes N");
  oneshot::OsrSettings osrSettings;
  if (denoiser) osrSettings.denoiser = oneshot::parseDenoiser(*denoiser);
  if (weights) {
    osrSettings.weightsPath = *weights;
    if (!denoiser) osrSettings.denoiser = oneshot::Denoiser::Unet;
  }
  if (gridStart) osrSettings.gridStart = uint32_t(*gridStart);
  if (gridMin)
    osrSettings.gridMin = uint32_t(*gridMin);
  else
    osrSettings.gridMin = std::min(osrSettings.gridMin, osrSettings.gridStart);
  // Given explicitly, a sample count holds for every pass.
  if (directSpp) osrSettings.directSamples = osrSettings.directSamplesLate = uint32_t(*directSpp);
  if (residualSpp)
    osrSettings.residualSamples = osrSettings.residualSamplesLate = uint32_t(*residualSpp);
  if (residualRamp) osrSettings.residualRamp = *residualRamp;
  if (mapSpp) osrSettings.pathsPerTexel = uint32_t(*mapSpp);
  if (mapShare) osrSettings.mapShare = *mapShare;
  if (osrSettings.gridMin > osrSettings.gridStart)
    throw InputError("--grid-min: " + std::to_string(osrSettings.gridMin) +
                     " is coarser than --grid-start " + std::to_string(osrSettings.gridStart));
  if (dumpMaps && !osrMode) throw InputError("--dump-maps: an option of --mode osr");
  const bool live = !exrPath && !pngPath;  // no output file: the viewer
  // Options that only shape a file which is not written would be ignored without a word.
  if (exposure && !live && !pngPath)
    throw InputError(
        "--exposure: sets the exposure of the --png preview (the EXR holds radiance); "
        "give --png too");
  if (exrFloat && !exrPath) throw InputError("--exr-float: an option of the --offline EXR");
  if (live && dumpMaps)
    throw InputError("--dump-maps: an option of --offline/--png renders (the viewer saves with S)");
  if (!live && (viewerScript || saveDir))
    throw InputError(
        "render: --viewer-script and --save-dir are options of the viewer "
        "(without --offline/--png)");
  // Checked now, not at the first save: every S in the window would fail with it.
  if (saveDir && !std::filesystem::is_directory(*saveDir))
    throw InputError("--save-dir: " + *saveDir + " is not a folder");
  if (live && crop) throw InputError("--crop: an option of --offline/--png renders");
  if (crop && (crop->size() != 4 || (*crop)[2] < 1 || (*crop)[3] < 1))
    throw InputError("--crop: expected X,Y,W,H (the window's corner and size, W and H >= 1)");
  if (frames) {
    if (live) throw InputError("--frames: an option of --offline/--png renders (give --offline)");
    if (dumpMaps) throw InputError("--dump-maps: not with --frames (one frame's maps)");
    if (exrPath) checkFrameField("--offline", *exrPath);
    if (pngPath) checkFrameField("--png", *pngPath);
  }
  if (live) {
    // Before any work: no display means one line suggesting --offline and exit 2.
    vkOptions.instanceExtensions = viewer::requireDisplay();
    vkOptions.swapchain = true;
  }

  HostScene host = loadHostScene(files[0], sceneOptions);
  if (crop) applyCrop(host, *crop);
  if (frames && host.scene.animation.empty())
    throw InputError(files[0] + ": --frames: the scene has no animation (no glTF animation " +
                     "channel moves a node's translation, rotation or scale)");
  // Fail before the (long) render, not after it, and never write over what the render reads.
  std::vector<OutputFile> outputs;
  // A shot checks every frame's files.
  for (int f = frames ? frames->first : 0; f <= (frames ? frames->last : 0); ++f) {
    if (exrPath) outputs.push_back({"--offline", frames ? framePath(*exrPath, f) : *exrPath, ".exr", "OpenEXR"});
    if (pngPath) outputs.push_back({"--png", frames ? framePath(*pngPath, f) : *pngPath, ".png", "PNG"});
  }
  if (dumpMaps) {
    // The folder is made now, not after the render: a path that cannot be one (an existing
    // file, a file on the way) is bad input found in a second, not an error after minutes.
    if (std::filesystem::exists(*dumpMaps) && !std::filesystem::is_directory(*dumpMaps))
      throw InputError("--dump-maps: " + *dumpMaps + " exists and is not a folder");
    std::error_code ec;
    std::filesystem::create_directories(*dumpMaps, ec);
    if (ec)
      throw InputError("--dump-maps: " + *dumpMaps + ": cannot create the folder (" + ec.message() +
                       ")");
    for (const char* name : {"oneshot.png", "clean.png", "grid.png"})
      outputs.push_back({"--dump-maps", *dumpMaps + "/" + name, ".png", "PNG"});
  }
  std::vector<NamedPath> inputs;
  for (const std::string& f : host.scene.files)
    inputs.push_back({f == files[0] ? "the scene" : "a file of the scene", f});
  if (host.env && !host.env->path.empty()) inputs.push_back({"the --env map", host.env->path});
  if (weights) inputs.push_back({"the --weights file", *weights});
  if (!denoise.networkFile.empty()) inputs.push_back({"the --network file", denoise.networkFile});
  checkOutputs(outputs, inputs);
  warnIfNeutralSky(host);
  const uint32_t imageWidth = host.width, imageHeight = host.height;
  // Units: samples per pixel (path, preview) or passes (osr). Preview is deterministic after
  // one sample per pixel but antialiases with more; OSR's defaults give a converged-looking
  // image in about the path tracer's default time.
  render::DriverSettings ds;
  ds.maxUnits = osrMode ? (passes ? uint32_t(*passes) : 32u)
                        : (spp ? uint32_t(*spp) : (*ptMode == pt::Mode::Preview ? 4u : 64u));
  if (timeLimit) {
    ds.timeLimitS = *timeLimit;
    if (!spp && !passes) ds.maxUnits = 1u << 24;  // --time alone: as many units as fit
  }
  // A unit longer than the batch target (an OSR pass at 4K takes minutes on lavapipe) runs in
  // slices, so progress lines keep coming during it. 16 for the first unit, before any is
  // timed: enough for progress, too few to cost a small render anything.
  ds.sliceUnits = true;
  ds.firstUnitSlices = 16;
  const uint32_t renderSeed = seed ? uint32_t(*seed) : 0u;

  vk::Context ctx(vkOptions);
  // Built at the first frame's pose for a shot, and again for each frame that moves geometry
  // or lights: integrators bind it, so one is never kept across a rebuild.
  std::optional<DeviceScene> dev;
  if (!frames) dev.emplace(ctx, host);
  // One factory for --offline and the viewer (which makes a new integrator on a mode change
  // or a resize).
  auto makeIntegrator = [&](const std::string& m, uint32_t w, uint32_t h) {
    viewer::IntegratorChoice c;
    if (m == "osr") {
      osrSettings.keepAllMaps = bool(dumpMaps);
      c.integrator =
          std::make_unique<oneshot::OsrIntegrator>(ctx, dev->gpu, dev->bvh, w, h, osrSettings);
      c.defaultUnits = 32;
    } else {
      const pt::Mode pm = *pt::parseMode(m);
      c.integrator = std::make_unique<pt::PathIntegrator>(ctx, dev->gpu, dev->bvh, w, h, pm);
      c.defaultUnits = pm == pt::Mode::Preview ? 4u : 64u;
    }
    return c;
  };
  if (live) {
    viewer::ViewerConfig vc;
    vc.scenePath = files[0];
    vc.scene = &host.scene;
    vc.camera = host.camera;
    vc.width = imageWidth;
    vc.height = imageHeight;
    vc.modes = {"path", "preview", "osr"};
    vc.mode = mode;
    vc.makeIntegrator = makeIntegrator;
    vc.maxUnits = ds.maxUnits;
    vc.timeLimitS = ds.timeLimitS;
    vc.seed = renderSeed;
    vc.exposureEv = exposure;
    vc.scriptPath = viewerScript.value_or("");
    vc.saveDir = saveDir.value_or(".");
    vc.denoise = denoise;
    return viewer::runViewer(ctx, vc);
  }
  osrSettings.resolveEverySubmission = false;  // nothing shows the film before the end
  // Made (and its model read) before the render: a bad --network file is refused at once.
  std::unique_ptr<render::Denoiser> imageDenoiser;
  if (denoise.active()) imageDenoiser = std::make_unique<render::Denoiser>(ctx, denoise, imageWidth, imageHeight);
  // A shot's frames share one integrator while the device scene stays: restart() clears every
  // accumulated state, and making one costs seconds of pipeline builds on lavapipe.
  std::unique_ptr<render::Integrator> integrator;
  // One image through `camera` into the given files, with its progress and summary lines.
  auto renderImage = [&](const scene::Camera& camera, const std::optional<std::string>& exrFile,
                         const std::optional<std::string>& pngFile) {
    ProgressPrinter progress(quiet, spp || passes || !timeLimit);
    if (!integrator) integrator = makeIntegrator(mode, imageWidth, imageHeight).integrator;
    auto* osr = dynamic_cast<oneshot::OsrIntegrator*>(integrator.get());
    render::ProgressiveDriver driver(ctx, *integrator, ds);
    driver.restart(camera, renderSeed);
    const render::RenderStats& stats = driver.run([&](const render::Progress& p) { progress(p); });
    render::FilmLayers film = integrator->resolve();
    if (imageDenoiser) imageDenoiser->apply(film);
    progress.finish();
    // The driver never stops inside a unit, and an image needs one whole: say why --time ran
    // over. (A quarter over: nearer, the budget's own rounding.)
    if (!quiet && timeLimit && stats.units == 1 && stats.seconds > 1.25 * *timeLimit)
      std::fprintf(stderr, "osr-vk: note: the image needs one whole %s, which took %.1f s, past --time %g\n",
                   osrMode ? "pass" : "sample per pixel", stats.seconds, *timeLimit);
    if (film.droppedSamples > 0)
      std::fprintf(stderr, "osr-vk: warning: %llu non-finite samples dropped\n",
                   static_cast<unsigned long long>(film.droppedSamples));
    if (exrFile)
      image::writeExr(*exrFile, render::toLayeredImage(film),
                      exrFloat ? image::ExrPixelType::Float : image::ExrPixelType::Half);
    if (pngFile)
      image::writePng(*pngFile, {film.width, film.height, film.combined}, exposure, film.depth);
    if (dumpMaps) writeMapDump(*dumpMaps, osr->downloadMaps(), film);
    if (!quiet) {
      std::fprintf(stderr, "osr-vk: %ux%u, %u %s in %.2f s", imageWidth, imageHeight, stats.units,
                   unitWord(integrator->unitName(), stats.units), stats.seconds);
      for (const auto& t : stats.gpuScopes)
        std::fprintf(stderr, ", %s %.0f ms", t.name.c_str(), t.ms);
      if (imageDenoiser)
        std::fprintf(stderr, ", denoise (%s) %.0f ms", imageDenoiser->name(), 1e3 * imageDenoiser->lastSeconds());
      std::fputc('\n', stderr);
    }
  };
  if (!frames) {
    renderImage(host.camera, exrPath, pngPath);
    return 0;
  }
  renderShot(*frames, host, quiet, exrPath, pngPath, [&](const scene::PoseChange& change) {
    // The BVH is rebuilt only when geometry moved; a light that moved needs the new upload too.
    if (!dev || change.geometry || change.lights) {
      integrator.reset();  // it binds the old scene
      dev.reset();
      dev.emplace(ctx, host);
    }
  }, renderImage);
  return 0;
}

}  // namespace osr::app
