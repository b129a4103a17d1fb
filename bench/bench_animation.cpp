// animation: a camera path rendered as frames (docs/animation.md "Temporal quality"). By
// default a held-out generated interior (tools/make_interiors.py seed 9002, daylight through
// two windows) with a 48-frame walk (tools/add_camera_path.py), both generated into the cache
// folder on first use, at 256 x 256. Each frame is a new image (restart, seed = frame + 1) as in
// `osr-vk --frames`; the sequences:
//   osr        OSR without the map cache, --passes per frame
//   osr+cache  OSR with the world-space map cache carried from frame to frame, --cache-passes
//   path       the path tracer for osr+cache's mean CPU seconds per frame (equal time)
//   path+atrous the same with the a-trous filter on each frame, its time included
//   path+network the same with the default learned denoiser (osr-vk --frames' default)
//   osr+network, osr+cache+network  the two OSR sequences with the default learned denoiser
//              on each frame (osr's default), its time included: whether the cache pays once
//              the direct light's noise, most of OSR's error at a few passes, is denoised
// and, per sequence: seconds per frame (wall and this process's CPU time: on shared cores the
// wall time of a frame moves with the others' load, the CPU time it took much less), relMSE on the reference frames, and flicker
// (render/flicker.h) between consecutive reference frames, measured on the pixels that the
// converged references' depth pairs; the converged sequence's own flicker is the floor of
// what the reprojection leaves (view-dependent shading, resampling). References are path
// traced at --reference-spp with other seeds and kept in the cache folder, keyed by the scene
// files' contents, the size and the sample count, so reruns skip them. Verified after the
// renders: every frame of every sequence has a finite mean luminance within a factor of 2 of
// its reference's.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <ctime>

#include "app/args.h"
#include "app/frames.h"
#include "app/integrators.h"
#include "app/scene_setup.h"
#include "bench/benchmarks.h"
#include "bench/json.h"
#include "common/error.h"
#include "common/fnv1a.h"
#include "image/image_io.h"
#include "image/image_metrics.h"
#include "osr/osr_integrator.h"
#include "render/camera_frame.h"
#include "render/denoiser.h"
#include "render/flicker.h"
#include "render/progressive_driver.h"
#include "render/temporal_reuse.h"
#include "scene/animation.h"

namespace osr::bench {

namespace {

namespace fs = std::filesystem;

constexpr int kDefaultSeed = 9002;  // a held-out interior (docs/training.md: validation seeds)
constexpr uint32_t kReferenceSeedBase = 1000003;  // references' noise independent of the runs'

// One rendered frame: its wall time and units; its colour only on reference frames.
struct FrameRun {
  double seconds = 0.0, cpuSeconds = 0.0;
  uint32_t units = 0;
  std::array<uint32_t, 4> cacheActions{};  // OSR with the cache: its last map pass's
  std::vector<float> rgb, depth;
};

// CPU time of this process, every thread (lavapipe's workers are threads of it).
double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// With `temporal`, the frame is blended with the ones before it, and with `denoiser`
// denoised, as osr-vk --frames does, inside its timed span.
FrameRun renderFrame(const vk::Context& ctx, render::Integrator& integrator,
                     const scene::Camera& cam, uint32_t seed, uint32_t maxUnits, double seconds,
                     render::Denoiser* denoiser = nullptr,
                     render::TemporalReuse* temporal = nullptr) {
  render::DriverSettings ds;
  ds.maxUnits = maxUnits;
  ds.timeLimitS = seconds;
  render::ProgressiveDriver driver(ctx, integrator, ds);
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();
  driver.restart(cam, seed);
  const render::RenderStats stats = driver.run();
  render::FilmLayers film = integrator.resolve();
  if (temporal) temporal->apply(film, render::makeFrame(cam, uint32_t(film.width), uint32_t(film.height), 0));
  if (denoiser) denoiser->apply(film);
  FrameRun r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.cpuSeconds = processCpuSeconds() - cpu0;
  if (auto* osr = dynamic_cast<oneshot::OsrIntegrator*>(&integrator))
    if (osr->mapCache()) r.cacheActions = osr->mapCacheActions();
  r.units = stats.units;
  r.rgb = std::move(film.combined);
  r.depth = std::move(film.depth);
  return r;
}

// Runs `command` (the default scene's generators); a failure is exit 1 naming it.
void runTool(const std::string& command) {
  if (std::system(command.c_str()) != 0)
    throw std::runtime_error("animation: generating the default scene failed: " + command);
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// The default scene and its environment, generated into `dir` unless already there.
std::pair<std::string, std::string> defaultScene(const fs::path& dir) {
  const std::string seed = std::to_string(kDefaultSeed);
  const fs::path interior = dir / "interiors" / seed;
  const fs::path walk = dir / ("walk" + seed + ".gltf");
  const std::string tools = std::string(OSR_SOURCE_DIR) + "/tools/";
  if (!fs::exists(interior / "scene.gltf"))
    runTool("python3 " + quoted(tools + "make_interiors.py") + " " +
            quoted((dir / "interiors").string()) + " --seeds " + seed + " >/dev/null");
  if (!fs::exists(walk))
    runTool("python3 " + quoted(tools + "add_camera_path.py") + " " +
            quoted((interior / "scene.gltf").string()) + " " + quoted(walk.string()) +
            " --frames 48");
  return {walk.string(), (interior / "sky.hdr").string()};
}

// FNV-1a over the files' bytes and `extra`: the references' cache key.
std::string contentKey(const std::vector<std::string>& files, const std::string& extra) {
  Fnv1a h;
  for (const std::string& f : files) {
    std::ifstream in(f, std::ios::binary);
    h.add(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  }
  h.add(extra);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h.value()));
  return hex;
}

image::LayeredImage rgbLayer(int w, int h, const std::vector<float>& rgb) {
  return image::LayeredImage{w, h, {image::ImageLayer{"", {"R", "G", "B"}, rgb}}, {}};
}

// A reference frame: read from `dir`, or path traced and written there.
FrameRun reference(const vk::Context& ctx, render::Integrator& path, const scene::Camera& cam,
                   int frame, uint32_t spp, uint32_t size, const fs::path& dir) {
  const std::string colour = app::framePath((dir / "frame_####.exr").string(), frame);
  const std::string depth = app::framePath((dir / "depth_####.exr").string(), frame);
  FrameRun r;
  if (image::isCompleteImage(colour) && image::isCompleteImage(depth)) {
    r.rgb = image::readExrRgb(colour).rgb;
    const std::vector<float> d3 = image::readExrRgb(depth).rgb;
    for (size_t i = 0; i < d3.size(); i += 3) r.depth.push_back(d3[i]);
    return r;
  }
  std::fprintf(stderr, "osr-bench: animation: reference frame %d, %u spp\n", frame, spp);
  r = renderFrame(ctx, path, cam, kReferenceSeedBase + uint32_t(frame), spp, 0.0);
  std::vector<float> d3;
  for (float d : r.depth) d3.insert(d3.end(), {d, d, d});
  image::writeExr(colour, rgbLayer(int(size), int(size), r.rgb), image::ExrPixelType::Float);
  image::writeExr(depth, rgbLayer(int(size), int(size), d3), image::ExrPixelType::Float);
  return r;
}

double meanOf(const std::vector<float>& rgb) {
  double s = 0.0;
  for (size_t i = 0; i < rgb.size(); i += 3) s += 0.2126 * rgb[i] + 0.7152 * rgb[i + 1] + 0.0722 * rgb[i + 2];
  return s / double(rgb.size() / 3);
}

}  // namespace

int runAnimation(const std::vector<std::string>& args) {
  app::Args a(args, "animation");
  const auto sceneArg = a.value("--scene");
  const auto envArg = a.value("--env");
  const uint32_t size = uint32_t(a.integer("--size", 8, 4096).value_or(256));
  const uint32_t passes = uint32_t(a.integer("--passes", 1, 4096).value_or(4));
  const auto cachePassesArg = a.integer("--cache-passes", 1, 4096);
  const uint32_t cacheMaps =
      uint32_t(a.integer("--map-cache", 4, 1 << 20).value_or(oneshot::kDefaultMapCacheMaps));
  const uint32_t maturePasses = uint32_t(
      a.integer("--mature-passes", 0, 4096).value_or(oneshot::kShotMatureMapPasses));
  const auto refFramesArg = a.integerList("--reference-frames", 0, 999999);
  const uint32_t refSpp = uint32_t(a.integer("--reference-spp", 1, 1 << 20).value_or(256));
  const auto cacheArg = a.value("--cache");
  const auto pngArg = a.value("--png");
  // Only the path-traced sequences, path tracing given this many samples a frame (else the
  // samples that take osr+cache's CPU time).
  const auto pathOnlySpp = a.integer("--path-only", 1, 1 << 20);
  const float history = float(a.number("--temporal-reuse", 0.5, 64.0).value_or(render::kDefaultTemporalHistory));
  const std::optional<app::FrameOptions> framesArg = app::readFrameOptions(a);
  a.finish();
  if (framesArg && framesArg->resume)
    throw InputError("--resume: not an option of osr-bench animation (references are cached)");
  app::FrameOptions frames;
  frames.first = 0;
  frames.last = 47;
  if (framesArg) frames = *framesArg;
  if (frames.count() < 2)
    throw InputError("--frames: the flicker needs at least two frames, got " +
                     std::to_string(frames.count()));
  const std::vector<long long> refList =
      refFramesArg.value_or(std::vector<long long>{24, 25, 26, 27});
  std::set<int> refFrames;
  for (long long f : refList) {
    if (f < frames.first || f > frames.last)
      throw InputError("--reference-frames: frame " + std::to_string(f) + " is outside --frames " +
                       std::to_string(frames.first) + "-" + std::to_string(frames.last));
    refFrames.insert(int(f));
  }
  if (std::none_of(refFrames.begin(), refFrames.end(), [&](int f) { return refFrames.count(f + 1) > 0; }))
    throw InputError("--reference-frames: the flicker needs two consecutive frames among them");
  const uint32_t cachePasses = uint32_t(cachePassesArg.value_or(std::max(1u, passes / 2)));

  const fs::path cacheDir = cacheArg ? fs::path(*cacheArg)
                                     : fs::temp_directory_path() / "osr-bench-animation";
  std::string scenePath, envPath;
  if (sceneArg) {
    scenePath = *sceneArg;
    if (envArg) envPath = *envArg;
  } else {
    fs::create_directories(cacheDir);
    std::tie(scenePath, envPath) = defaultScene(cacheDir);
    if (envArg) envPath = *envArg;
  }
  app::SceneOptions so;
  if (!envPath.empty()) so.env = envPath;
  so.width = size;
  so.height = size;
  app::HostScene host = app::loadHostScene(scenePath, so);
  const scene::Animation& anim = host.scene.animation;
  if (anim.empty())
    throw InputError(scenePath + ": the scene has no animation (no glTF animation channel moves " +
                     "a node's translation, rotation or scale)");
  if (!anim.movesCameras() || host.camera.fileIndex < 0)
    throw InputError(scenePath + ": no animated camera (osr-bench animation renders a camera path; " +
                     "tools/add_camera_path.py adds one)");
  if (anim.movesGeometry())
    throw InputError(scenePath + ": the animation moves meshes or lights; osr-bench animation " +
                     "measures a camera-only path (the map cache is kept only across those)");
  if (pngArg) fs::create_directories(*pngArg);

  // The camera of every frame, posed as renderShot poses it.
  std::map<int, scene::Camera> cameras;
  for (int f = frames.first; f <= frames.last; ++f) {
    scene::poseScene(host.scene, frames.timeS(f));
    scene::Camera cam = host.camera;
    for (const scene::Camera& c : host.scene.cameras)
      if (c.fileIndex == host.camera.fileIndex) cam.worldFromCamera = c.worldFromCamera;
    cameras[f] = cam;
  }

  vk::Context ctx;
  app::DeviceScene device(ctx, host);
  const app::IntegratorScene onDevice{ctx, device.gpu, device.bvh};
  app::IntegratorSettings settings = app::buildIntegratorSettings(app::IntegratorOptions{});
  settings.offline = true;
  auto path = app::makeIntegrator(onDevice, settings, "path", size, size);

  // References, cached by content.
  std::vector<std::string> keyFiles = host.scene.files;
  if (!envPath.empty()) keyFiles.push_back(envPath);
  const fs::path refDir =
      cacheDir / "references" /
      contentKey(keyFiles, std::to_string(size) + " " + std::to_string(refSpp) + " " +
                               std::to_string(frames.fps));
  fs::create_directories(refDir);
  std::map<int, FrameRun> refs;
  for (int f : refFrames) refs[f] = reference(ctx, *path, cameras[f], f, refSpp, size, refDir);

  // Pixel pairs of consecutive reference frames, from the references' depth.
  std::map<int, std::vector<render::PixelPair>> pairs;  // by the later frame
  auto view = [&](int f) {
    return render::DepthView{render::makeFrame(cameras[f], size, size, 0), &refs[f].depth};
  };
  for (int f : refFrames)
    if (refFrames.count(f - 1)) pairs[f] = render::reprojectPairs(view(f), view(f - 1));

  struct Sequence {
    std::string name;
    std::vector<FrameRun> frames;  // by frame - frames.first
    double meanSeconds = 0.0, meanCpuSeconds = 0.0;
  };
  // Each sequence starts with an untimed frame of one unit: the first dispatches of a process
  // on lavapipe pay for more than the frame (about 20 s at 64 x 64), which would not be the
  // integrator's. The cache is emptied after it.
  auto runSequence = [&](const std::string& name, render::Integrator& integrator,
                         uint32_t units, render::Denoiser* denoiser = nullptr,
                         render::TemporalReuse* temporal = nullptr) {
    renderFrame(ctx, integrator, cameras[frames.first], 1, 1, 0.0, denoiser, temporal);
    if (auto* osr = dynamic_cast<oneshot::OsrIntegrator*>(&integrator))
      if (oneshot::MapCache* cache = osr->mapCache()) cache->clear(ctx);
    if (temporal) temporal->forget();
    Sequence s;
    s.name = name;
    for (int f = frames.first; f <= frames.last; ++f) {
      FrameRun r = renderFrame(ctx, integrator, cameras[f], uint32_t(f) + 1, units, 0.0, denoiser, temporal);
      if (!refFrames.count(f)) r.rgb.clear(), r.depth.clear();
      s.meanSeconds += r.seconds / frames.count();
      s.meanCpuSeconds += r.cpuSeconds / frames.count();
      s.frames.push_back(std::move(r));
    }
    std::fprintf(stderr, "osr-bench: animation: %s, %d frames, %.3g s (%.3g CPU s) per frame\n",
                 name.c_str(), frames.count(), s.meanSeconds, s.meanCpuSeconds);
    return s;
  };

  // OSR without and with the cache; each sequence's warm-up empties the cache, so the
  // denoised sequences below start from nothing too.
  app::IntegratorSettings osrSettings = settings;
  osrSettings.osr.mapCacheMaps = 0;
  app::IntegratorSettings cacheSettings = settings;
  cacheSettings.osr.mapCacheMaps = cacheMaps;
  cacheSettings.osr.mapCacheMaturePasses = maturePasses;
  std::unique_ptr<render::Integrator> osr, cached;
  std::vector<Sequence> sequences;
  if (!pathOnlySpp) {
    osr = app::makeIntegrator(onDevice, osrSettings, "osr", size, size);
    cached = app::makeIntegrator(onDevice, cacheSettings, "osr", size, size);
    sequences.push_back(runSequence("osr", *osr, passes));
    sequences.push_back(runSequence("osr+cache", *cached, cachePasses));
  }
  // Equal time in CPU seconds: the samples per pixel that take osr+cache's CPU time per frame,
  // from the path tracer's CPU time per sample on frame first (8 spp, after a warm-up).
  renderFrame(ctx, *path, cameras[frames.first], 1, 1, 0.0);
  const double cpuPerSpp = renderFrame(ctx, *path, cameras[frames.first], 1, 8, 0.0).cpuSeconds / 8.0;
  const double frameCpu = pathOnlySpp ? *pathOnlySpp * cpuPerSpp : sequences[1].meanCpuSeconds;
  const uint32_t pathSpp = uint32_t(std::max(1.0, std::round(frameCpu / cpuPerSpp)));
  sequences.push_back(runSequence("path", *path, pathSpp));
  // The denoised sequences, as osr-vk --frames gives them: path tracing with the a-trous
  // filter, and with the default learned denoiser (the filter below its fewest samples). The
  // denoiser's CPU time comes out of the samples (the second of two runs: the first makes its
  // pipelines).
  // The samples a denoised frame gets for `share` of frameCpu, with temporal reuse's time paid
  // too when there is one.
  auto denoisedSpp = [&](render::Denoiser& denoiser, double share = 1.0,
                         render::TemporalReuse* temporal = nullptr) {
    double extraCpu = 0.0;
    for (int i = 0; i < 2; ++i) {
      render::FilmLayers film = path->resolve();
      const double cpu0 = processCpuSeconds();
      if (temporal)
        temporal->apply(film, render::makeFrame(cameras[frames.first], size, size, 0));
      denoiser.apply(film);
      extraCpu = processCpuSeconds() - cpu0;
    }
    if (temporal) temporal->forget();
    // A share below 1 is "at most": rounded down.
    const double spp = (share * frameCpu - extraCpu) / cpuPerSpp;
    return uint32_t(std::max(1.0, share < 1.0 ? std::floor(spp) : std::round(spp)));
  };
  render::DenoiseSettings filterSettings;
  filterSettings.atrous = true;
  {
    render::Denoiser denoiser(ctx, filterSettings, size, size);
    sequences.push_back(runSequence("path+atrous", *path, denoisedSpp(denoiser), &denoiser));
  }
  if (render::defaultImageModel()) {
    render::DenoiseSettings networkSettings = filterSettings;
    networkSettings.network = render::DenoiseSettings::Network::Default;
    render::Denoiser denoiser(ctx, networkSettings, size, size);
    const uint32_t spp = denoisedSpp(denoiser);
    sequences.push_back(runSequence("path+network", *path, spp, &denoiser));
    // osr-vk --frames' default: the same with temporal reuse, at half the CPU time a frame.
    render::TemporalReuse temporal(ctx, size, size, history);
    sequences.push_back(runSequence("path+reuse+network", *path,
                                    denoisedSpp(denoiser, 0.5, &temporal), &denoiser, &temporal));
    if (!pathOnlySpp) {
      // OSR blends its residual for the denoiser, as osr-vk --frames does with one.
      for (render::Integrator* i : {osr.get(), cached.get()})
        static_cast<oneshot::OsrIntegrator&>(*i).setResidualNoiseWeight(oneshot::kDenoisedResidualNoiseWeight);
      sequences.push_back(runSequence("osr+network", *osr, passes, &denoiser));
      sequences.push_back(runSequence("osr+cache+network", *cached, cachePasses, &denoiser));
    }
  }

  // Verification: a render whose mean is far from its reference's is broken, not noisy.
  for (const Sequence& s : sequences)
    for (int f : refFrames) {
      const double ratio = meanOf(s.frames[f - frames.first].rgb) / meanOf(refs[f].rgb);
      if (!std::isfinite(ratio) || ratio < 0.5 || ratio > 2.0) {
        std::fprintf(stderr,
                     "osr-bench: animation: verification failed (%s frame %d: mean luminance "
                     "%.4g of the reference's)\n",
                     s.name.c_str(), f, ratio);
        return kExitInternal;
      }
    }

  const std::string sceneName = sceneArg ? *sceneArg : "interior" + std::to_string(kDefaultSeed);
  auto line = [&](const std::string& sequence) {
    JsonLine j;
    j.str("bench", "animation").str("scene", sceneName).integer("size", size).str("sequence", sequence);
    return j;
  };
  auto flickerOf = [&](auto&& rgbOf) {
    double sum = 0.0;
    for (const auto& [f, pp] : pairs) sum += render::flicker(pp, rgbOf(f), rgbOf(f - 1), refs[f].rgb);
    return sum / double(pairs.size());
  };
  double pairedShare = 0.0;
  for (const auto& [f, pp] : pairs) pairedShare += double(pp.size()) / (double(size) * size * pairs.size());
  std::map<std::string, double> flickers, relMeans;
  for (const Sequence& s : sequences) {
    const bool isPath = s.name.rfind("path", 0) == 0;
    double relSum = 0.0;
    for (int f : refFrames) {
      const FrameRun& r = s.frames[f - frames.first];
      const double rel = image::relMse({int(size), int(size), r.rgb}, {int(size), int(size), refs[f].rgb});
      relSum += rel / double(refFrames.size());
      line(s.name).integer("frame", f).num("seconds", r.seconds).num("cpu_seconds", r.cpuSeconds).num("relmse", rel)
          .integer(isPath ? "spp" : "passes", r.units).str("device", ctx.caps().deviceName).print();
      if (pngArg) {
        const double ev = image::autoExposureEv({int(size), int(size), refs[f].rgb}, refs[f].depth);
        std::string tag = s.name;
        std::replace(tag.begin(), tag.end(), '+', '_');
        image::writePng(app::framePath(*pngArg + "/" + tag + "_###.png", f), {int(size), int(size), r.rgb}, ev);
        if (s.name == sequences.front().name)
          image::writePng(app::framePath(*pngArg + "/reference_###.png", f), {int(size), int(size), refs[f].rgb}, ev);
      }
    }
    double warm = 0.0;  // frames after the first: the cache's steady state
    uint64_t units = 0;
    std::array<uint64_t, 4> actions{};
    for (size_t i = 0; i < s.frames.size(); ++i) {
      if (i) warm += s.frames[i].seconds / double(s.frames.size() - 1);
      units += s.frames[i].units;
      for (int k = 0; k < 4; ++k) actions[k] += s.frames[i].cacheActions[k];
    }
    relMeans[s.name] = relSum;
    flickers[s.name] = flickerOf([&](int f) -> const std::vector<float>& { return s.frames[f - frames.first].rgb; });
    line(s.name).integer("frames", frames.count()).num("seconds_per_frame", s.meanSeconds)
        .num("seconds_per_frame_after_first", warm).num("cpu_seconds_per_frame", s.meanCpuSeconds)
        .num(isPath ? "spp_per_frame" : "passes_per_frame", double(units) / frames.count())
        .num("relmse_mean", relSum).num("flicker", flickers[s.name])
        .integer("flicker_pairs", long(pairs.size())).num("paired_pixel_share", pairedShare)
        .integer("cache_reused", long(actions[gpu::osr::kMapCacheReuse]))
        .integer("cache_refined", long(actions[gpu::osr::kMapCacheRefine]))
        .integer("cache_inserted", long(actions[gpu::osr::kMapCacheInsert]))
        .integer("cache_traced_unstored", long(actions[gpu::osr::kMapCacheTrace]))
        .str("device", ctx.caps().deviceName).print();
  }
  flickers["converged"] = flickerOf([&](int f) -> const std::vector<float>& { return refs[f].rgb; });
  line("converged").integer("reference_spp", refSpp).num("flicker", flickers["converged"])
      .integer("flicker_pairs", long(pairs.size())).str("device", ctx.caps().deviceName).print();
  JsonLine summary = line("summary");
  const auto named = [&](const std::string& name) -> const Sequence* {
    for (const Sequence& s : sequences)
      if (s.name == name) return &s;
    return nullptr;
  };
  if (const Sequence *plain = named("osr"), *cached = named("osr+cache"); plain && cached)
    summary.num("cache_seconds_ratio", cached->meanSeconds / plain->meanSeconds)
        .num("cache_cpu_seconds_ratio", cached->meanCpuSeconds / plain->meanCpuSeconds)
        .num("cache_flicker_over_path", flickers["osr+cache"] / flickers["path"])
        .num("nocache_flicker_over_path", flickers["osr"] / flickers["path"]);
  summary.num("path_atrous_flicker_over_path", flickers["path+atrous"] / flickers["path"]);
  if (flickers.count("path+network"))
    summary.num("path_network_flicker_over_path", flickers["path+network"] / flickers["path"]);
  // Temporal reuse's question: half the samples a frame, and what that costs in error.
  if (const Sequence *plain = named("path+network"), *reused = named("path+reuse+network");
      plain && reused)
    summary.num("reuse_cpu_seconds_ratio", reused->meanCpuSeconds / plain->meanCpuSeconds)
        .num("reuse_relmse_ratio", relMeans[reused->name] / relMeans[plain->name])
        .num("reuse_flicker_ratio", flickers[reused->name] / flickers[plain->name])
        .num("temporal_reuse", history);
  // The cache's question once denoised: half the passes, and what that costs in error.
  summary.integer("passes", passes).integer("cache_passes", cachePasses).integer("map_cache", cacheMaps)
      .integer("mature_passes", maturePasses)
      .str("device", ctx.caps().deviceName).print();
  return kExitOk;
}

}  // namespace osr::bench
