// denoise: the image denoisers at equal wall-clock time (docs/denoise.md). For a scene and
// each time budget, one JSON line per row: path tracing and OSR, each raw, + the a-trous
// filter and + the image network, each with relMSE against a reference EXR and the
// denoiser's own time; a denoised row also with the relMSE of the same film before the
// denoiser's two convergence passes (render/denoise_passes.h BiasPass, ConvergePass). A
// denoised row renders for the budget minus the denoiser's time (measured once per denoiser
// at this size, after a warm-up run), so the denoise is paid out of the budget.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "app/args.h"
#include "bench/bench_scene.h"
#include "bench/benchmarks.h"
#include "bench/json.h"
#include "bvh/bvh.h"
#include "common/error.h"
#include "image/image_io.h"
#include "image/image_metrics.h"
#include "osr/osr_integrator.h"
#include "pt/path_integrator.h"
#include "render/denoiser.h"
#include "render/progressive_driver.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"

namespace osr::bench {

namespace {

render::FilmLayers renderFor(const vk::Context& ctx, render::Integrator& integrator,
                             const scene::Camera& cam, double seconds, render::RenderStats& stats) {
  return renderFilm(ctx, integrator, cam, 1, 1u << 24, std::max(seconds, 0.001), stats);
}

// The denoiser's wall time on a film of this size: the second of two runs (the first makes
// pipelines and touches memory).
double denoiseSeconds(render::Denoiser& d, const render::FilmLayers& film) {
  for (int run = 0; run < 2; ++run) {
    render::FilmLayers f = film;
    f.samples = std::max(f.samples, render::kDenoiseProbeSamples);  // every pass runs
    d.apply(f);
  }
  return d.lastSeconds();
}

}  // namespace

int runDenoise(const std::vector<std::string>& args) {
  app::Args a(args, "denoise");
  const SceneArgs sceneArgs = readSceneArgs(a);
  const uint32_t size = uint32_t(a.integer("--size", 8, 4096).value_or(256));
  auto budgets = a.integerList("--budgets", 1, 3600).value_or(std::vector<long long>{5, 10, 30});
  const std::string network = a.value("--network").value_or("default");
  const std::optional<std::string> rowsArg = a.value("--rows");
  a.finish();
  const std::string& sceneArg = sceneArgs.name;
  const render::DenoiseSettings netSettings = networkSettings(network);
  render::DenoiseSettings filterSettings;
  filterSettings.atrous = true;

  vk::Context ctx;
  const BenchScene bs(ctx, sceneArgs, size);
  const scene::Camera& cam = bs.camera;
  const image::RgbImage& ref = bs.reference;
  oneshot::OsrSettings osrSettings;
  osrSettings.resolveEverySubmission = false;  // as --offline
  oneshot::OsrIntegrator osr(ctx, *bs.gpu, *bs.bvh, size, size, osrSettings);
  pt::PathIntegrator path(ctx, *bs.gpu, *bs.bvh, size, size, pt::Mode::Path);
  render::Denoiser filter(ctx, filterSettings, size, size);
  std::unique_ptr<render::Denoiser> net;
  if (netSettings.network != render::DenoiseSettings::Network::None)
    net = std::make_unique<render::Denoiser>(ctx, netSettings, size, size);

  // Denoiser times, on a short path render of this scene.
  render::RenderStats warm;
  const render::FilmLayers sample = renderFor(ctx, path, cam, 0.5, warm);
  const double filterS = denoiseSeconds(filter, sample);
  const double netS = net ? denoiseSeconds(*net, sample) : 0.0;

  struct Row {
    const char* name;
    render::Integrator* integrator;
    render::Denoiser* denoiser;
    double denoiseS;
  };
  std::vector<Row> allRows = {{"path", &path, nullptr, 0.0}, {"path+atrous", &path, &filter, filterS},
                              {"osr", &osr, nullptr, 0.0}, {"osr+atrous", &osr, &filter, filterS}};
  if (net) {
    allRows.push_back({"path+network", &path, net.get(), netS});
    allRows.push_back({"osr+network", &osr, net.get(), netS});
  }
  // --rows picks from the list in its order; the network rows exist only with a network.
  std::vector<Row> rows = rowsArg ? std::vector<Row>{} : allRows;
  std::stringstream names(rowsArg.value_or(""));
  for (std::string name; std::getline(names, name, ',');) {
    auto it = std::find_if(allRows.begin(), allRows.end(), [&](const Row& r) { return name == r.name; });
    if (it == allRows.end())
      throw InputError("--rows: unknown row '" + name + "' (path, path+atrous, osr, osr+atrous" +
                       (net ? ", path+network, osr+network)" : "; network rows need a --network)"));
    rows.push_back(*it);
  }
  for (long long budget : budgets) {
    for (const Row& row : rows) {
      // OSR blends its residual for the denoiser that follows, as osr-vk does.
      const float osrWeight = oneshot::residualNoiseWeightFor(row.denoiser != nullptr);
      osr.setResidualNoiseWeight(osrWeight);
      render::RenderStats stats;
      render::FilmLayers film = renderFor(ctx, *row.integrator, cam, double(budget) - row.denoiseS, stats);
      const double raw = image::relMse({int(size), int(size), film.combined}, ref);
      std::vector<float> unconverged;
      if (row.denoiser) row.denoiser->apply(film, &unconverged);
      image::RgbImage img{int(size), int(size), film.combined};
      JsonLine j;
      j.str("bench", "denoise")
          .str("scene", sceneArg)
          .str("reference", bs.referenceName)
          .str("row", row.name)
          .integer("size", size)
          .integer("budget_s", budget)
          .num("render_s", stats.seconds)
          .num("denoise_s", row.denoiser ? row.denoiser->lastSeconds() : 0.0)
          .num("relmse", image::relMse(img, ref))
          .num("relmse_raw", raw)
          .num("lum_ratio", image::meanLuminance(img) / image::meanLuminance(ref))
          .integer(row.integrator == &osr ? "passes" : "spp", stats.units);
      if (row.denoiser) j.num("relmse_unconverged", image::relMse({int(size), int(size), unconverged}, ref));
      if (row.integrator == &osr) j.num("residual_noise_weight", osrWeight);
      if (row.denoiser == net.get() && net) j.str("network", network);
      if (bs.referenceNoise) j.num("ref_noise", *bs.referenceNoise).str("ref_noise_from", bs.referenceNoiseFrom);
      j.str("device", ctx.caps().deviceName).print();
    }
  }
  return kExitOk;
}

}  // namespace osr::bench
