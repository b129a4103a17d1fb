// osr: One Shot Radiance against the path tracer at equal wall-clock time, on the reference
// scenes (256 x 256, the Cycles references' size): for each scene and time budget, one JSON
// line per mode with relMSE against the 4096-spp Cycles reference, passes or samples done,
// and for OSR the GPU time per pass kind (gbuffer, direct, maps, normalize, unet, denoise,
// project, composite, residual, resolve), maps traced per second, and the wall time of the
// first (noise-free) image. Verified before timing: 8 OSR passes at 32 x 32 must be finite
// and within 15% of the reference's mean luminance.
//   osr-bench osr [--scene cornell|room] [--size N] [--budgets 2,5,10,30,60]
//                 [--denoiser blur|none|unet] [--weights FILE] [--modes osr,path]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "app/args.h"
#include "app/integrators.h"
#include "bench/benchmarks.h"
#include "bench/json.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "image/image_io.h"
#include "image/image_metrics.h"
#include "osr/osr_integrator.h"
#include "render/progressive_driver.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"

namespace osr::bench {

namespace {

std::string referencePath(const std::string& name, const std::string& file) {
  return std::string(OSR_SOURCE_DIR) + "/scenes/" + name + "/" + file;
}

struct Run {
  render::FilmLayers film;
  render::RenderStats stats;
  uint64_t maps = 0;
};

Run runFor(const vk::Context& ctx, render::Integrator& integrator, const scene::Camera& cam,
           double budgetS, uint32_t maxUnits) {
  render::DriverSettings ds;
  ds.timeLimitS = budgetS;
  ds.maxUnits = maxUnits;
  render::ProgressiveDriver driver(ctx, integrator, ds);
  driver.restart(cam, 1);
  Run r;
  r.stats = driver.run();
  r.film = integrator.resolve();
  return r;
}

}  // namespace

int runOsr(const std::vector<std::string>& args) {
  app::Args a(args, "osr");
  auto sceneName = a.value("--scene");
  uint32_t size = uint32_t(a.integer("--size", 8, 4096).value_or(256));
  auto budgets =
      a.integerList("--budgets", 1, 3600).value_or(std::vector<long long>{2, 5, 10, 30, 60});
  auto denoiser = a.value("--denoiser");
  auto weights = a.value("--weights");
  std::string modes = a.value("--modes").value_or("osr,path");
  a.finish();
  if (modes != "osr,path" && modes != "osr" && modes != "path")
    throw InputError("--modes: expected osr,path, osr or path, got '" + modes + "'");
  // Settings as `osr-vk render --offline` builds them from the same options.
  app::IntegratorOptions options;
  options.osr.denoiser = denoiser;
  options.osr.weights = weights;
  app::IntegratorSettings settings = app::buildIntegratorSettings(options);
  settings.offline = true;
  std::vector<std::string> names = sceneName ? std::vector<std::string>{*sceneName}
                                             : std::vector<std::string>{"cornell", "room"};
  vk::Context ctx;
  for (const std::string& name : names) {
    scene::Scene sc = scene::loadScene(referencePath(name, name + ".gltf"));
    scene::Camera cam = scene::selectCamera(sc, "", 1.f);
    scene::GpuScene gs(ctx, sc);
    bvh::Bvh tree = bvh::buildGpu(ctx, gs.vertices, gs.triangles, gs.triangleCount);
    image::RgbImage ref = image::readExrRgb(referencePath(name, name + "_cycles_4096spp.exr"));
    const app::IntegratorScene onDevice{ctx, gs, tree};
    {
      auto check = app::makeIntegrator(onDevice, settings, "osr", 32, 32);
      Run r = runFor(ctx, *check, cam, 0.0, 8);
      double ratio = image::meanLuminance({32, 32, r.film.combined}) / image::meanLuminance(ref);
      if (!std::isfinite(ratio) || std::abs(ratio - 1.0) > 0.15) {
        std::fprintf(stderr,
                     "osr-bench: osr %s: verification failed (mean luminance %.4g of "
                     "the reference's)\n",
                     name.c_str(), ratio);
        return kExitInternal;
      }
    }
    auto osrIntegrator = app::makeIntegrator(onDevice, settings, "osr", size, size);
    auto& osr = dynamic_cast<oneshot::OsrIntegrator&>(*osrIntegrator);
    auto path = app::makeIntegrator(onDevice, settings, "path", size, size);
    // The first image: one pass, wall time from restart to the resolved film on the host.
    double firstImageS;
    {
      auto t0 = std::chrono::steady_clock::now();
      Run r = runFor(ctx, osr, cam, 0.0, 1);
      firstImageS = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    for (long long budget : budgets) {
      for (const char* mode : {"osr", "path"}) {
        if (modes.find(mode) == std::string::npos) continue;
        const bool isOsr = std::string(mode) == "osr";
        render::Integrator& integrator = isOsr ? *osrIntegrator : *path;
        Run r = runFor(ctx, integrator, cam, double(budget), 1u << 24);
        image::RgbImage img{int(size), int(size), r.film.combined};
        JsonLine j;
        j.str("bench", "osr")
            .str("scene", name)
            .str("mode", mode)
            .integer("size", size)
            .integer("budget_s", budget)
            .num("seconds", r.stats.seconds)
            .num("relmse", image::relMse(img, ref))
            .num("lum_ratio", image::meanLuminance(img) / image::meanLuminance(ref))
            .integer(isOsr ? "passes" : "spp", r.stats.units);
        if (isOsr) {
          j.str("denoiser", oneshot::denoiserName(settings.osr.denoiser))
              .num("first_image_s", firstImageS);
          const double mapMs = r.stats.gpuMs("maps");
          j.integer("maps", long(osr.mapsTraced()))
              .num("maps_per_s", mapMs > 0 ? osr.mapsTraced() / (mapMs * 1e-3) : 0.0);
          for (const auto& t : r.stats.gpuScopes) j.num((t.name + "_ms").c_str(), t.ms);
        }
        j.str("device", ctx.caps().deviceName).print();
      }
    }
  }
  return kExitOk;
}

}  // namespace osr::bench
