// osr-vk [options] scene.gltf: loads the scene, builds the BVH, renders progressively with
// the chosen integrator and writes the multi-layer OpenEXR (--offline) and a PNG preview.
// Output paths are checked before any work, and files are written through a temporary name,
// so a failed render leaves existing files untouched. --time and Ctrl-C stop a render within
// about a submission, even inside an OSR pass (DriverSettings::stopInUnit), and what was
// rendered is written (README "Stopping a render").
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <optional>

#include "app/commands.h"
#include "app/frames.h"
#include "app/integrators.h"
#include "app/interrupt.h"
#include "app/output_paths.h"
#include "app/render_options.h"
#include "app/scene_setup.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "common/fnv1a.h"
#include "common/input_file.h"
#include "image/image_io.h"
#include "osr/osr_integrator.h"
#include "render/camera_frame.h"
#include "render/film_export.h"
#include "render/progressive_driver.h"
#include "render/temporal_reuse.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"
#include "viewer/viewer.h"
#include "viewer/window.h"
#include "vk/context.h"

namespace osr::app {

namespace fs = std::filesystem;

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

// The scene on the host, its film cropped to the --crop window; a shot needs an animation.
HostScene loadRenderScene(const RenderOptions& o) {
  HostScene host = loadHostScene(o.scenePath, o.scene);
  if (o.crop) applyCrop(host, *o.crop);
  if (o.frames && host.scene.animation.empty())
    throw InputError(o.scenePath + ": --frames: the scene has no animation (no glTF animation " +
                     "channel moves a node's translation, rotation or scale)");
  return host;
}

// Fail before the (long) render, not after it, and never write over what the render reads.
void checkRenderFiles(const RenderOptions& o, const HostScene& host) {
  std::vector<OutputFile> outputs;
  // A shot checks every frame's files.
  const auto& fr = o.frames;
  for (int f = fr ? fr->first : 0; f <= (fr ? fr->last : 0); ++f) {
    if (o.exrPath)
      outputs.push_back({"--offline", fr ? framePath(*o.exrPath, f) : *o.exrPath, ".exr", "OpenEXR"});
    if (o.pngPath)
      outputs.push_back({"--png", fr ? framePath(*o.pngPath, f) : *o.pngPath, ".png", "PNG"});
  }
  if (o.dumpMaps) {
    const std::string& dir = *o.dumpMaps;
    // The folder is made now, not after the render: a path that cannot be one (an existing
    // file, a file on the way) is bad input found in a second, not an error after minutes.
    if (auto problem = folderProblem(dir)) throw InputError("--dump-maps: " + dir + *problem);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec)
      throw InputError("--dump-maps: " + dir + ": cannot create the folder (" + ec.message() +
                       ")");
    for (const char* name : {"oneshot.png", "clean.png", "grid.png"})
      outputs.push_back({"--dump-maps", dir + "/" + name, ".png", "PNG"});
  }
  std::vector<NamedPath> inputs;
  for (const std::string& f : host.scene.files)
    inputs.push_back({f == o.scenePath ? "the scene" : "a file of the scene", f});
  if (host.env && !host.env->path.empty()) inputs.push_back({"the --env map", host.env->path});
  if (o.integrator.osr.weights) inputs.push_back({"the --weights file", *o.integrator.osr.weights});
  if (!o.integrator.everyMode.denoise.networkFile.empty())
    inputs.push_back({"the --network file", o.integrator.everyMode.denoise.networkFile});
  checkOutputs(outputs, inputs);
}

// The stop rules: the unit count given or the mode's default, --time (alone: as many units as
// fit). A unit longer than the batch target (an OSR pass at 4K takes minutes on lavapipe) runs
// in slices, so progress lines keep coming during it. Offline, --time or Ctrl-C stops even a
// unit part-way, so slices are many where pixels are (about 2048 pixels a slice, recorded in
// groups of about the batch target: a first OSR pass at 4K in 4096 slices, at 512 x 512 in
// 128, whose extra dispatches cost little; under 4096 pixels none). The viewer finishes a
// unit it started.
render::DriverSettings driverSettings(const RenderOptions& o, const IntegratorSettings& settings,
                                      uint64_t pixels) {
  render::DriverSettings ds;
  ds.maxUnits = settings.unitsOrDefault();
  if (o.timeLimit) {
    ds.timeLimitS = *o.timeLimit;
    if (!settings.units) ds.maxUnits = 1u << 24;
  }
  ds.sliceUnits = true;
  if (!o.live()) {
    ds.stopInUnit = true;
    ds.maxSlices = uint32_t(std::clamp<uint64_t>(pixels / 2048, 1, 4096));
  }
  return ds;
}

int runLive(const RenderOptions& o, const IntegratorSettings& settings, const HostScene& host,
            const vk::Context& ctx) {
  const DeviceScene dev(ctx, host);
  const IntegratorScene scene{ctx, dev.gpu, dev.bvh};
  const render::DriverSettings ds = driverSettings(o, settings, uint64_t(host.width) * host.height);
  viewer::ViewerConfig vc;
  vc.scenePath = o.scenePath;
  vc.scene = &host.scene;
  vc.camera = host.camera;
  vc.width = host.width;
  vc.height = host.height;
  vc.modes = integratorNames();
  vc.mode = o.integrator.mode;
  vc.makeIntegrator = viewerFactory(scene, settings);
  vc.maxUnits = ds.maxUnits;
  vc.timeLimitS = ds.timeLimitS;
  vc.seed = uint32_t(o.seed.value_or(0));
  vc.exposureEv = o.exposure;
  vc.scriptPath = o.viewerScript.value_or("");
  vc.saveDir = o.saveDir.value_or(".");
  vc.denoise = o.integrator.everyMode.denoise;
  return viewer::runViewer(ctx, vc);
}

// Thrown when Ctrl-C or SIGTERM stopped the render (after writing what was rendered, for one
// image); runRender exits 128 + the signal.
struct Interrupted {
  int signal;
};

// Offline renders: one image, or a shot's frames. The device scene is built at the first
// frame's pose for a shot, and again for each frame that moves geometry or lights. A shot's
// frames share one integrator: restart() clears every accumulated state, making one costs
// seconds of pipeline builds on lavapipe, and OSR's map cache carries maps from frame to
// frame. After a rebuild the integrator renders the new scene where it can rebind to it (the path
// tracer; OSR, which drops the cached maps near what moved); else it is made again.
class OfflineRenderer {
 public:
  OfflineRenderer(const RenderOptions& o, const IntegratorSettings& settings, HostScene& host,
                  const vk::Context& ctx)
      : o_(o), settings_(settings), host_(host), ctx_(ctx) {
    settings_.offline = true;  // nothing shows the film before the end
    // Made (and its model read) before the render: a bad --network file is refused at once.
    if (o.integrator.everyMode.denoise.active())
      imageDenoiser_ = std::make_unique<render::Denoiser>(ctx, o.integrator.everyMode.denoise,
                                                          host.width, host.height);
    // Which denoiser --time affords, before any integrator: OSR blends its residual for the
    // denoiser that will run (OsrSettings::residualNoiseWeight).
    if (o.timeLimit && imageDenoiser_) denoiseReserveS_ = denoiseReserve();
    settings_.osr.residualNoiseWeight = oneshot::residualNoiseWeightFor(imageDenoiser_ != nullptr);
  }
  // The seconds --time holds back for the denoiser, which runs after the budget: its time on a
  // small image (run twice, the first builds its pipelines) scaled by the pixels, timed on a
  // film with enough samples that the network runs where there is one (the dearer of the two
  // path's default holds). A default network that would take more than half the budget gives
  // way to the filter, and a default filter that would is dropped, each with a warning; a
  // denoiser asked for is kept.
  double denoiseReserve() {
    render::DenoiseSettings settings = o_.integrator.everyMode.denoise;
    const double pixels = double(host_.width) * host_.height;
    const auto estimate = [&](const render::DenoiseSettings& s) {
      constexpr int kProbe = 128;
      render::Denoiser probe(ctx_, s, kProbe, kProbe);
      render::FilmLayers empty;
      empty.allocate(kProbe, kProbe);
      empty.samples = render::kDenoiseProbeSamples;
      probe.apply(empty);
      probe.apply(empty);
      return probe.lastSeconds() * pixels / (kProbe * kProbe);
    };
    double seconds = estimate(settings);
    if (settings.chosen || seconds <= 0.5 * *o_.timeLimit) return seconds;
    const auto warn = [&](const char* what, const char* instead) {
      std::fprintf(stderr,
                   "osr-vk: warning: --time %g: the default %s would take about %.0f s of it at %ux%u; %s "
                   "(--network or --filter to insist)\n",
                   *o_.timeLimit, what, seconds, host_.width, host_.height, instead);
    };
    if (settings.network != render::DenoiseSettings::Network::None && settings.atrous) {
      warn("network", "the a-trous filter instead");
      settings.network = render::DenoiseSettings::Network::None;
      imageDenoiser_ = std::make_unique<render::Denoiser>(ctx_, settings, host_.width, host_.height);
      seconds = estimate(settings);
      if (seconds <= 0.5 * *o_.timeLimit) return seconds;
    }
    warn(settings.network != render::DenoiseSettings::Network::None ? "network" : "a-trous filter", "not denoised");
    imageDenoiser_.reset();
    return 0.0;
  }
  // One image through `camera` into the given files, with its progress and summary lines.
  void renderImage(const scene::Camera& camera, const std::optional<std::string>& exrFile,
                   const std::optional<std::string>& pngFile);
  // The shot of --frames, each frame by renderImage.
  void renderFrames();

 private:
  // The film's render: progress lines, notes on a render stopped part-way, dropped samples.
  render::RenderStats render(const scene::Camera& camera, render::FilmLayers& film);
  void notePartialUnit(const render::RenderStats& stats) const;
  void write(render::FilmLayers&& film, const render::RenderStats& stats,
             const std::optional<std::string>& exrFile,
             const std::optional<std::string>& pngFile) const;
  void printSummary(const render::RenderStats& stats) const;
  // The file of the history after `frame`, beside the shot's first output: two, by the frame's
  // parity (.shot_####.exr.history0 and 1), each written before its frame's images, so that
  // the one after the last complete frame survives a stop at any point.
  std::string historyPath(int frame) const;
  uint64_t shotKey() const;
  // Takes the history after `frame` from its file where it is this shot's.
  void restoreHistory(int frame);

  const RenderOptions& o_;
  IntegratorSettings settings_;
  HostScene& host_;
  const vk::Context& ctx_;
  std::optional<DeviceScene> dev_;
  std::unique_ptr<render::Integrator> integrator_;
  std::unique_ptr<render::Denoiser> imageDenoiser_;
  std::unique_ptr<render::TemporalReuse> temporal_;  // a shot's, unless --temporal-reuse 0
  bool keepHistory_ = false;  // the history is written beside the frames (renderFrames)
  uint64_t historyKey_ = 0;
  std::optional<int> shotFrame_;  // the frame renderImage renders, in a shot
  double historySaveS_ = 0.0;     // seconds the last frame's history took to write
  double denoiseReserveS_ = 0.0;  // seconds --time holds back for the image denoiser
};

void OfflineRenderer::renderImage(const scene::Camera& camera,
                                  const std::optional<std::string>& exrFile,
                                  const std::optional<std::string>& pngFile) {
  if (!dev_) dev_.emplace(ctx_, host_);
  if (!integrator_)
    integrator_ = makeIntegrator({ctx_, dev_->gpu, dev_->bvh}, settings_, o_.integrator.mode,
                                 host_.width, host_.height);
  render::FilmLayers film;
  const render::RenderStats stats = render(camera, film);
  // A shot's frame stopped by a signal is not written: --resume would take it for complete.
  if (o_.frames && interrupt::stopSignal()) throw Interrupted{interrupt::stopSignal()};
  if (keepHistory_ && shotFrame_) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<uint8_t> bytes = temporal_->save(*shotFrame_, historyKey_);
    image::writeFileAtomic(historyPath(*shotFrame_), bytes.data(), bytes.size());
    historySaveS_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  write(std::move(film), stats, exrFile, pngFile);
  printSummary(stats);
  // A signal while writing lets the write finish, then exits as one during the render.
  if (interrupt::stopSignal()) throw Interrupted{interrupt::stopSignal()};
}

void OfflineRenderer::renderFrames() {
  auto prepare = [&](const scene::PoseChange& change) {
    // The BVH is rebuilt only when geometry moved; a light that moved needs the new upload too.
    if (dev_ && !change.geometry && !change.lights) return;
    // The old scene goes first (the integrator records nothing until rebound): one device
    // scene at a time.
    dev_.reset();
    dev_.emplace(ctx_, host_);
    if (integrator_ && !integrator_->rebind(dev_->gpu, dev_->bvh, change)) integrator_.reset();
    // What the frames before saw is not this scene's light.
    if (temporal_) temporal_->forget();
  };
  // The preview's image is not light; it has nothing to gather over frames.
  if (o_.frames->temporalHistory > 0.0f && o_.integrator.mode != "preview")
    temporal_ = std::make_unique<render::TemporalReuse>(ctx_, host_.width, host_.height,
                                                        o_.frames->temporalHistory);
  // The history is kept beside the frames, so that --resume continues the shot as if it had
  // not stopped (renderImage). A shot whose meshes or lights move forgets it at each such
  // frame, and a resumed run of one starts without it.
  keepHistory_ = temporal_ && !host_.scene.animation.movesGeometry();
  if (keepHistory_) historyKey_ = shotKey();
  std::optional<int> previous;
  renderShot(*o_.frames, host_, o_.quiet, o_.exrPath, o_.pngPath, prepare,
             [&](int frame, const scene::Camera& camera, const std::optional<std::string>& exrFile,
                 const std::optional<std::string>& pngFile) {
               if (temporal_ && previous != frame - 1) {
                 temporal_->forget();
                 if (keepHistory_ && o_.frames->resume && frame > o_.frames->first)
                   restoreHistory(frame - 1);
               }
               shotFrame_ = frame;
               renderImage(camera, exrFile, pngFile);
               previous = frame;
             });
  // The shot is complete: nothing left to resume.
  for (int parity = 0; parity < 2 && keepHistory_; ++parity) {
    std::error_code ec;
    fs::remove(historyPath(parity), ec);
  }
}

std::string OfflineRenderer::historyPath(int frame) const {
  const fs::path first(o_.exrPath ? *o_.exrPath : *o_.pngPath);
  const std::string name = "." + first.filename().string() + ".history" + std::to_string(frame & 1);
  return (first.parent_path() / name).string();
}

// FNV-1a over what makes a frame's light: the scene's files (path, size, modification time),
// the environment, the image size, mode, seed, samples or passes and --time. A history of
// another shot is not taken (other options of a mode are not in it).
uint64_t OfflineRenderer::shotKey() const {
  Fnv1a h;
  const auto mix = [&](const std::string& s) { h.add(s).add("\xff"); };  // 0xff ends each
  std::vector<std::string> files = host_.scene.files;
  if (o_.scene.env) files.push_back(*o_.scene.env);
  for (const std::string& f : files) {
    std::error_code ec;
    mix(f);
    mix(std::to_string(fs::file_size(f, ec)));
    mix(std::to_string(fs::last_write_time(f, ec).time_since_epoch().count()));
  }
  mix(std::to_string(host_.width) + "x" + std::to_string(host_.height) + " " + o_.integrator.mode +
      " " + std::to_string(o_.seed.value_or(0)) + " " + std::to_string(settings_.unitsOrDefault()) + " " +
      std::to_string(o_.timeLimit.value_or(0.0)));
  return h.value();
}

void OfflineRenderer::restoreHistory(int frame) {
  const std::string file = historyPath(frame);
  std::ifstream in(file, std::ios::binary);
  if (!in) return;  // the run stopped before that frame's history
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (temporal_->restore(bytes, frame, historyKey_)) return;
  if (!o_.quiet)
    std::fprintf(stderr,
                 "osr-vk: note: %s is not the history after frame %d of this shot; frame %d starts "
                 "without one\n",
                 file.c_str(), frame, frame + 1);
}

render::RenderStats OfflineRenderer::render(const scene::Camera& camera,
                                            render::FilmLayers& film) {
  ProgressPrinter progress(o_.quiet, settings_.units || !o_.timeLimit);
  render::DriverSettings ds = driverSettings(o_, settings_, uint64_t(host_.width) * host_.height);
  // The image's layers are made before the render, and --time holds back what resolving,
  // converting and writing them will take: on lavapipe 6 to 10 times as long as the first
  // touch of the layers, from 768 x 768 to 3840 x 2160 (docs/device_notes.md, "Stopping a 4K
  // render"), whatever the machine's load, since both are host work over the same pixels.
  const auto allocStart = std::chrono::steady_clock::now();
  film.allocate(int(host_.width), int(host_.height));
  const double allocS =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - allocStart).count();
  constexpr double kFinishOverAllocate = 10.0;
  if (o_.timeLimit) ds.reserveS = kFinishOverAllocate * allocS;
  ds.reserveS += denoiseReserveS_;
  // A shot's frame also blends in the frames before it and keeps the history for --resume:
  // as long as the last frame's took.
  if (o_.timeLimit && temporal_) ds.reserveS += temporal_->lastSeconds() + historySaveS_;
  // One image: --time counts from the start of osr-vk, set-up included (a frame of a shot: from
  // its own start); the first submission runs whatever is left.
  if (!o_.frames) ds.budgetStart = o_.started;
  render::ProgressiveDriver driver(ctx_, *integrator_, ds);
  // With temporal reuse a shot's frames each draw other samples (--seed plus the frame
  // number): with one seed, consecutive frames' noise is alike, and blending them would count
  // the same noise twice.
  const uint32_t frameSeed = temporal_ ? uint32_t(shotFrame_.value_or(0)) : 0u;
  driver.restart(camera, uint32_t(o_.seed.value_or(0)) + frameSeed);
  interrupt::renderLoopStarts();
  const auto sinceStart = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - o_.started).count();
  };
  const double loopStart = sinceStart();
  const render::RenderStats stats =
      driver.run([&](const render::Progress& p) { progress(p); }, interrupt::stopFlag());
  // Where the budget went, on --time's clock (from osr-vk's start): set-up, the render loop,
  // and the seconds held back after it.
  if (o_.timeLimit && !o_.frames && !o_.quiet)
    std::fprintf(stderr,
                 "osr-vk: note: --time %g: the render loop ran from %.2f to %.2f s, holding back "
                 "%.2f s for the resolve and write\n",
                 *o_.timeLimit, loopStart, sinceStart(), ds.reserveS);
  integrator_->resolveInto(film);
  if (temporal_)
    temporal_->apply(film, render::makeFrame(camera, host_.width, host_.height, 0));
  if (imageDenoiser_) imageDenoiser_->apply(film);
  progress.finish();
  notePartialUnit(stats);
  if (film.droppedSamples > 0)
    std::fprintf(stderr, "osr-vk: warning: %llu non-finite samples dropped\n",
                 static_cast<unsigned long long>(film.droppedSamples));
  return stats;
}

// A render that --time or a signal stopped inside a unit: what the unit left in the image.
// Without a complete unit the image is unfinished, which a warning says even with --quiet.
void OfflineRenderer::notePartialUnit(const render::RenderStats& stats) const {
  if (stats.abandonedFraction <= 0.0) return;
  const char* by = stats.stoppedBy != render::StopReason::Cancelled ? "--time"
                   : interrupt::stopSignal() == SIGTERM          ? "SIGTERM"
                                                                 : "Ctrl-C";
  const double percent = 100.0 * stats.abandonedFraction;
  if (stats.units == 0)
    std::fprintf(stderr,
                 "osr-vk: warning: %s stopped the first %s at %.0f%% after %.1f s: the image is "
                 "unfinished (black where it did not reach)\n",
                 by, settings_.kind->oneUnit, percent, stats.seconds);
  else if (!o_.quiet)
    std::fprintf(stderr, "osr-vk: note: %s stopped %.0f%% into the %s after %u; %s\n", by,
                 percent, settings_.kind->oneUnit, stats.units,
                 settings_.kind->dropsPartialUnit
                     ? "it is dropped: the image is of the complete ones"
                     : "the pixels it reached have one sample more than the others");
}

// How the image was made, in the EXR header: the mode, the complete units under the unit
// option's name (osr-vk:passes, osr-vk:spp), the share of a unit stopped part-way that the
// image holds (0 when none or dropped), what stopped the render and its seconds.
std::vector<image::ExrAttribute> renderAttributes(const IntegratorSettings& settings,
                                                  const render::RenderStats& stats) {
  const std::string unit = std::string("osr-vk:") + (settings.kind->unitOption + 2);
  const bool keptPartial = stats.units == 0 || !settings.kind->dropsPartialUnit;
  const char* stop = stats.stoppedBy == render::StopReason::Cancelled ? "signal"
                     : stats.stoppedBy == render::StopReason::Time    ? "time"
                                                                      : "units";
  return {{"osr-vk:mode", std::string(settings.kind->name)},
          {unit, int(stats.units)},
          {"osr-vk:partial", float(keptPartial ? stats.abandonedFraction : 0.0)},
          {"osr-vk:stopped-by", std::string(stop)},
          {"osr-vk:seconds", float(stats.seconds)}};
}

void OfflineRenderer::write(render::FilmLayers&& film, const render::RenderStats& stats,
                            const std::optional<std::string>& exrFile,
                            const std::optional<std::string>& pngFile) const {
  if (pngFile)
    image::writePng(*pngFile, {film.width, film.height, film.combined}, o_.exposure, film.depth);
  if (o_.dumpMaps)
    writeMapDump(*o_.dumpMaps,
                 dynamic_cast<const oneshot::OsrIntegrator&>(*integrator_).downloadMaps(), film);
  // Last, since the image takes the film's layers.
  if (exrFile) {
    image::LayeredImage img = render::toLayeredImage(std::move(film));
    img.attributes = renderAttributes(settings_, stats);
    // A shot's frame with temporal reuse holds more than its own samples where it took history.
    if (temporal_) {
      img.attributes.push_back({"osr-vk:temporal-reuse", o_.frames->temporalHistory});
      img.attributes.push_back({"osr-vk:reused-share", float(temporal_->reusedShare())});
    }
    image::writeExr(*exrFile, img,
                    o_.exrFloat ? image::ExrPixelType::Float : image::ExrPixelType::Half);
  }
}

void OfflineRenderer::printSummary(const render::RenderStats& stats) const {
  if (o_.quiet) return;
  std::fprintf(stderr, "osr-vk: %ux%u, %u %s in %.2f s", host_.width, host_.height, stats.units,
               unitWord(integrator_->unitName(), stats.units), stats.seconds);
  for (const auto& t : stats.gpuScopes)
    std::fprintf(stderr, ", %s %.0f ms", t.name.c_str(), t.ms);
  if (imageDenoiser_)
    std::fprintf(stderr, ", denoise (%s) %.0f ms", imageDenoiser_->name(),
                 1e3 * imageDenoiser_->lastSeconds());
  std::fputc('\n', stderr);
}

}  // namespace

int runRender(const std::vector<std::string>& args) {
  RenderOptions options = parseRenderOptions(args);
  const IntegratorSettings settings = checkRenderOptions(options);
  // The viewer's display is required before any work: none means one line suggesting
  // --offline and exit 2.
  if (options.live()) {
    options.device.instanceExtensions = viewer::requireDisplay();
    options.device.swapchain = true;
  }
  HostScene host = loadRenderScene(options);
  checkRenderFiles(options, host);
  warnIfNeutralSky(host);
  if (!options.live()) interrupt::install();
  vk::Context ctx(options.device);
  if (options.live()) return runLive(options, settings, host, ctx);
  // Device loss and running out of memory: one line naming the failure and the image size;
  // the outputs are written only after a whole render, so none is changed.
  const std::string image = std::to_string(host.width) + "x" + std::to_string(host.height) +
                            " " + options.integrator.mode + " render";
  try {
    OfflineRenderer renderer(options, settings, host, ctx);
    if (options.frames)
      renderer.renderFrames();
    else
      renderer.renderImage(host.camera, options.exrPath, options.pngPath);
  } catch (const Interrupted& i) {
    std::fprintf(stderr, "osr-vk: interrupted (%s)%s\n", i.signal == SIGTERM ? "SIGTERM" : "SIGINT",
                 options.frames ? ": the frame in progress is not written" : "");
    return 128 + i.signal;
  } catch (const DeviceError& e) {
    throw DeviceError(image + " failed: " + e.what() + "; no output written");
  } catch (const std::bad_alloc&) {
    throw DeviceError(image + " failed: out of host memory; no output written");
  }
  return 0;
}

}  // namespace osr::app
