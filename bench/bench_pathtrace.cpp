// pathtrace: samples per pixel per second and Mpaths/s of the path tracer on the reference
// scenes (256 x 256 by default, the references' size). The output is verified before it is
// timed: a short render must be finite and within 10% of the Cycles reference's mean
// luminance. When `blender` is on PATH, Cycles renders the same glTF with the same size,
// samples and thread count (the cores of this machine) in the same run and a peer="cycles"
// line reports its figures and the ratio ours / Cycles.
//   osr-bench pathtrace [--scene cornell|room] [--size N] [--spp N]
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "app/args.h"
#include "image/image_io.h"
#include "image/image_metrics.h"
#include "bench/benchmarks.h"
#include "bench/bvh_scenes.h"
#include "bench/json.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "pt/path_integrator.h"
#include "scene_gpu/gpu_scene.h"
#include "scene/scene.h"

namespace osr::bench {

namespace {

std::string scenePath(const std::string& name, const std::string& file) {
  return std::string(OSR_SOURCE_DIR) + "/scenes/" + name + "/" + file;
}

bool haveBlender() {
  return std::system("command -v blender >/dev/null 2>&1") == 0;
}

// Renders the glTF with Cycles (CPU, box filter 1 px, 64 bounces, no denoising or adaptive
// sampling, as scenes/README.md describes the references) and returns the render time in
// seconds as Blender reports it, excluding start-up and import; < 0 on failure.
double timeCycles(const std::string& gltf, uint32_t size, uint32_t spp) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("osr_bench_cycles_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path script = dir / "cycles.py";
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  {
    FILE* f = std::fopen(script.c_str(), "w");
    if (!f) return -1;
    std::fprintf(f,
                 "import bpy, time\n"
                 "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
                 "bpy.ops.import_scene.gltf(filepath=%s)\n"
                 "s = bpy.context.scene\n"
                 "s.camera = next(o for o in s.objects if o.type == 'CAMERA')\n"
                 "s.render.engine = 'CYCLES'\n"
                 "s.cycles.device = 'CPU'\n"
                 "s.cycles.samples = %u\n"
                 "s.cycles.use_adaptive_sampling = False\n"
                 "s.cycles.use_denoising = False\n"
                 "s.cycles.max_bounces = 64\n"
                 "s.cycles.diffuse_bounces = s.cycles.glossy_bounces = 64\n"
                 "s.cycles.transmission_bounces = s.cycles.volume_bounces = 64\n"
                 "s.cycles.transparent_max_bounces = 64\n"
                 "s.cycles.sample_clamp_direct = s.cycles.sample_clamp_indirect = 0.0\n"
                 "s.cycles.filter_width = 1.0\n"
                 "s.render.threads_mode = 'FIXED'\n"
                 "s.render.threads = %u\n"
                 "s.render.resolution_x = s.render.resolution_y = %u\n"
                 "s.render.resolution_percentage = 100\n"
                 "s.render.filepath = %s\n"
                 "t = time.perf_counter()\n"
                 "bpy.ops.render.render(write_still=True)\n"
                 "print('OSR_CYCLES_SECONDS', time.perf_counter() - t)\n",
                 ("'" + gltf + "'").c_str(), spp, threads, size,
                 ("'" + (dir / "cycles.exr").string() + "'").c_str());
    std::fclose(f);
  }
  std::string cmd = "blender -b --factory-startup --python " + script.string() + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  double seconds = -1;
  std::array<char, 1024> line;
  while (fgets(line.data(), line.size(), p))
    if (std::sscanf(line.data(), "OSR_CYCLES_SECONDS %lf", &seconds) == 1) {
    }
  pclose(p);
  fs::remove_all(dir);
  return seconds;
}

}  // namespace

int runPathtrace(const std::vector<std::string>& args) {
  app::Args a(args, "pathtrace");
  auto sceneName = a.value("--scene");
  uint32_t size = uint32_t(a.integer("--size", 8, 4096).value_or(256));
  uint32_t spp = uint32_t(a.integer("--spp", 1, 1 << 20).value_or(8));
  a.finish();
  std::vector<std::string> names = sceneName ? std::vector<std::string>{*sceneName}
                                             : std::vector<std::string>{"cornell", "room"};
  vk::Context ctx;
  const bool blender = haveBlender();
  for (const std::string& name : names) {
    std::string gltf = scenePath(name, name + ".gltf");
    scene::Scene sc = scene::loadScene(gltf);
    scene::Camera cam = scene::selectCamera(sc, "", 1.f);
    scene::GpuScene gs(ctx, sc);
    bvh::Bvh tree = bvh::buildGpu(ctx, gs.vertices, gs.triangles, gs.triangleCount);
    pt::RenderSettings s;

    // Verify: 4 spp at 32 x 32 against the reference's mean luminance.
    s.width = s.height = 32;
    s.spp = 4;
    render::FilmLayers check = pt::render(ctx, gs, tree, cam, s);
    image::RgbImage ref = image::readExrRgb(scenePath(name, name + "_cycles_4096spp.exr"));
    double ours = image::meanLuminance({32, 32, check.combined});
    double ratio = ours / image::meanLuminance(ref);
    if (!std::isfinite(ours) || check.droppedSamples || std::abs(ratio - 1.0) > 0.1) {
      std::fprintf(stderr,
                   "osr-bench: pathtrace %s: verification failed (mean luminance %.4g "
                   "of the reference's, %llu dropped samples)\n",
                   name.c_str(), ratio, static_cast<unsigned long long>(check.droppedSamples));
      return 1;
    }

    s.width = s.height = size;
    s.spp = spp;
    render::RenderStats stats;
    // Process CPU time of the render (pipeline creation included): on a shared machine it
    // compares runs better than wall time.
    double cpuStart = processCpuMs();
    pt::render(ctx, gs, tree, cam, s, {}, &stats);
    double cpuMs = processCpuMs() - cpuStart;
    double sppPerS = stats.units / stats.seconds;
    double mpaths = sppPerS * size * size * 1e-6;
    JsonLine()
        .str("bench", "pathtrace")
        .str("scene", name)
        .integer("width", size)
        .integer("height", size)
        .integer("spp", stats.units)
        .num("seconds", stats.seconds)
        .num("gpu_ms", stats.gpuMs("pt_trace"))
        .num("cpu_time_ms", cpuMs)
        .num("spp_per_s", sppPerS)
        .num("mpaths_per_s", mpaths)
        .str("device", ctx.caps().deviceName)
        .print();
    if (blender) {
      double cs = timeCycles(gltf, size, spp);
      if (cs > 0) {
        JsonLine()
            .str("bench", "pathtrace")
            .str("peer", "cycles")
            .str("scene", name)
            .integer("width", size)
            .integer("height", size)
            .integer("spp", spp)
            .num("seconds", cs)
            .num("spp_per_s", spp / cs)
            .num("mpaths_per_s", spp / cs * size * size * 1e-6)
            .num("ratio_ours_over_cycles", sppPerS / (spp / cs))
            .str("device", "Blender Cycles CPU, " +
                               std::to_string(std::thread::hardware_concurrency()) + " threads")
            .print();
      } else {
        std::fprintf(stderr, "osr-bench: pathtrace %s: blender found but the Cycles run failed\n",
                     name.c_str());
      }
    }
  }
  if (!blender) std::fprintf(stderr, "osr-bench: pathtrace: blender not on PATH, no Cycles peer\n");
  return 0;
}

}  // namespace osr::bench
