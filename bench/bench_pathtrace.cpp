// pathtrace: the path tracer against Blender Cycles on the reference scenes (256 x 256 by
// default, the references' size). The output is verified before it is timed: a short render
// must be finite and within 10% of the Cycles reference's mean luminance. Then, per scene, one
// JSON line per renderer: ours at --spp samples (spp/s, Mpaths/s, relMSE against the 4096-spp
// reference) and, when `blender` is on PATH (Debian: apt-get install blender), Cycles at the
// same samples with the same size, filter, bounces and thread count (the cores of this
// machine), its relMSE, and ours at Cycles' render time (equal-time relMSE, its spp) in the
// same run.
//   osr-bench pathtrace [--scene cornell|room] [--size N] [--spp N]
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "app/args.h"
#include "app/integrators.h"
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

// What one Cycles render gave: its render time as Blender reports it (excluding start-up and
// import; < 0 on failure) and the image.
struct CyclesRun {
  double seconds = -1;
  image::RgbImage image;
};

// Renders the glTF with Cycles as scenes/README.md describes the references: CPU, Blackman-
// Harris filter of width 1 px, 64 bounces, no clamping, denoising or adaptive sampling, and
// non-metals (no metallic, specular or transmission, as Blender's exporter writes a Diffuse
// BSDF) as Blender's Lambertian Diffuse BSDF: Blender 3.4's glTF importer turns every material
// into a Principled BSDF, whose diffuse is not Lambertian (+7% on cornell).
CyclesRun runCycles(const std::string& gltf, uint32_t size, uint32_t spp) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("osr_bench_cycles_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path script = dir / "cycles.py";
  fs::path out = dir / "cycles.exr";
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  CyclesRun run;
  {
    FILE* f = std::fopen(script.c_str(), "w");
    if (!f) return run;
    std::fprintf(f,
                 "import bpy, time, numpy\n"
                 // Debian's Blender 3.4.1 glTF importer still uses numpy.bool, which numpy
                 // 1.24 (Debian 12) removed: restore the alias it meant.
                 "if 'bool' not in numpy.__dict__: numpy.bool = bool\n"
                 "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
                 "bpy.ops.import_scene.gltf(filepath=%s)\n"
                 "def lambertian(nt):\n"
                 "    for p in [n for n in nt.nodes if n.type == 'BSDF_PRINCIPLED']:\n"
                 "        p.distribution = 'GGX'\n"
                 "        if any(p.inputs[k].is_linked or p.inputs[k].default_value != 0.0\n"
                 "               for k in ('Metallic', 'Specular', 'Transmission')):\n"
                 "            continue\n"
                 "        outs = [l.to_socket for l in p.outputs['BSDF'].links]\n"
                 "        diff = nt.nodes.new('ShaderNodeBsdfDiffuse')\n"
                 "        emit = nt.nodes.new('ShaderNodeEmission')\n"
                 "        add = nt.nodes.new('ShaderNodeAddShader')\n"
                 "        for dst, src in ((diff.inputs['Color'], 'Base Color'),\n"
                 "                         (diff.inputs['Normal'], 'Normal'),\n"
                 "                         (emit.inputs['Color'], 'Emission'),\n"
                 "                         (emit.inputs['Strength'], 'Emission Strength')):\n"
                 "            if p.inputs[src].is_linked:\n"
                 "                nt.links.new(p.inputs[src].links[0].from_socket, dst)\n"
                 "            elif src != 'Normal':\n"
                 "                dst.default_value = p.inputs[src].default_value\n"
                 "        nt.links.new(diff.outputs[0], add.inputs[0])\n"
                 "        nt.links.new(emit.outputs[0], add.inputs[1])\n"
                 "        for o in outs: nt.links.new(add.outputs[0], o)\n"
                 "        nt.nodes.remove(p)\n"
                 "for m in bpy.data.materials:\n"
                 "    if m.use_nodes: lambertian(m.node_tree)\n"
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
                 "s.cycles.pixel_filter_type = 'BLACKMAN_HARRIS'\n"
                 "s.cycles.filter_width = 1.0\n"
                 "s.render.threads_mode = 'FIXED'\n"
                 "s.render.threads = %u\n"
                 "s.render.resolution_x = s.render.resolution_y = %u\n"
                 "s.render.resolution_percentage = 100\n"
                 "s.render.image_settings.file_format = 'OPEN_EXR'\n"
                 "s.render.image_settings.color_depth = '32'\n"
                 "s.render.filepath = %s\n"
                 "t = time.perf_counter()\n"
                 "bpy.ops.render.render(write_still=True)\n"
                 "print('OSR_CYCLES_SECONDS', time.perf_counter() - t)\n",
                 ("'" + gltf + "'").c_str(), spp, threads, size,
                 ("'" + out.string() + "'").c_str());
    std::fclose(f);
  }
  std::string cmd = "blender -b --factory-startup --python " + script.string() + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return run;
  double seconds = -1;
  std::array<char, 1024> line;
  while (fgets(line.data(), line.size(), p))
    if (std::sscanf(line.data(), "OSR_CYCLES_SECONDS %lf", &seconds) == 1) {
    }
  pclose(p);
  if (seconds > 0 && fs::exists(out)) {
    run.image = image::readExrRgb(out.string());
    run.seconds = seconds;
  }
  fs::remove_all(dir);
  return run;
}

}  // namespace

int runPathtrace(const std::vector<std::string>& args) {
  app::Args a(args, "pathtrace");
  auto sceneName = a.value("--scene");
  uint32_t size = uint32_t(a.integer("--size", 8, 4096).value_or(256));
  uint32_t spp =
      uint32_t(a.integer("--spp", 1, 1 << 20).value_or(app::integratorKind("path").defaultUnits));
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
    double checkLum = image::meanLuminance({32, 32, check.combined});
    double ratio = checkLum / image::meanLuminance(ref);
    if (!std::isfinite(checkLum) || check.droppedSamples || std::abs(ratio - 1.0) > 0.1) {
      std::fprintf(stderr,
                   "osr-bench: pathtrace %s: verification failed (mean luminance %.4g "
                   "of the reference's, %llu dropped samples)\n",
                   name.c_str(), ratio, static_cast<unsigned long long>(check.droppedSamples));
      return 1;
    }

    s.width = s.height = size;
    s.spp = spp;
    // relMSE against the reference needs its size (256 x 256); other sizes report speed only.
    const bool compare = ref.width == int(size) && ref.height == int(size);
    auto relmse = [&](const std::vector<float>& rgb) {
      return image::relMse({int(size), int(size), rgb}, ref);
    };
    render::RenderStats stats;
    // Process CPU time of the render (pipeline creation included): on a shared machine it
    // compares runs better than wall time.
    double cpuStart = processCpuMs();
    render::FilmLayers ours = pt::render(ctx, gs, tree, cam, s, {}, &stats);
    double cpuMs = processCpuMs() - cpuStart;
    double sppPerS = stats.units / stats.seconds;
    JsonLine line;
    line.str("bench", "pathtrace")
        .str("scene", name)
        .str("renderer", "osr-vk")
        .integer("width", size)
        .integer("height", size)
        .integer("spp", stats.units)
        .num("seconds", stats.seconds)
        .num("gpu_ms", stats.gpuMs("pt_trace"))
        .num("cpu_time_ms", cpuMs)
        .num("spp_per_s", sppPerS)
        .num("mpaths_per_s", sppPerS * size * size * 1e-6);
    if (compare) line.num("relmse", relmse(ours.combined));
    CyclesRun cycles;
    if (blender) {
      cycles = runCycles(gltf, size, spp);
      if (cycles.seconds <= 0)
        std::fprintf(stderr, "osr-bench: pathtrace %s: blender found but the Cycles run failed\n",
                     name.c_str());
    }
    if (cycles.seconds > 0 && compare) {
      // Ours for as long as Cycles took (equal time), in the same run.
      pt::RenderSettings e = s;
      e.spp = 1u << 20;
      e.timeLimitS = cycles.seconds;
      render::RenderStats es;
      render::FilmLayers equal = pt::render(ctx, gs, tree, cam, e, {}, &es);
      line.num("equal_time_s", es.seconds)
          .integer("equal_time_spp", es.units)
          .num("equal_time_relmse", relmse(equal.combined));
    }
    line.str("device", ctx.caps().deviceName).print();
    if (cycles.seconds > 0) {
      double cyclesSppPerS = spp / cycles.seconds;
      JsonLine c;
      c.str("bench", "pathtrace")
          .str("scene", name)
          .str("renderer", "cycles")
          .integer("width", size)
          .integer("height", size)
          .integer("spp", spp)
          .num("seconds", cycles.seconds)
          .num("spp_per_s", cyclesSppPerS)
          .num("mpaths_per_s", cyclesSppPerS * size * size * 1e-6)
          .num("ratio_spp_per_s_ours_over_cycles", sppPerS / cyclesSppPerS);
      if (compare) {
        double cyclesRelmse = image::relMse(cycles.image, ref);
        c.num("relmse", cyclesRelmse)
            .num("ratio_relmse_ours_over_cycles_equal_spp", relmse(ours.combined) / cyclesRelmse);
      }
      c.str("device", "Blender Cycles CPU, " +
                          std::to_string(std::thread::hardware_concurrency()) + " threads")
          .print();
    }
  }
  if (!blender) std::fprintf(stderr, "osr-bench: pathtrace: blender not on PATH, no Cycles peer\n");
  return 0;
}

}  // namespace osr::bench
