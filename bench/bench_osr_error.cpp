// osr-error: where OSR's error is (docs/osr.md, "Where the error is"). For each budget, the
// passes OSR makes in it (seed 1), or each of --passes (load-independent), then that many
// passes with --seeds seeds, and again with maps of --map-spp paths per texel. Over the seeds, each pixel's sample variance splits the
// mean relMSE of one render exactly into noise (the variance) and bias (the squared error of
// the seeds' mean less its own noise share):
//   relmse = noise + bias,  noise = direct + indirect + cross (the two layers' covariance),
//   indirect = maps' paths + maps' placement + residual,
// where the composite's noise (the indirect layer without the residual, over the same map
// passes) is the maps' paths' (what more paths per texel remove, scaled to all of it:
// (V(1) - V(k)) k / (k - 1)) and the maps' placement (the grid points jitter with the seed,
// so each seed interpolates between other points), and the residual's is what the residual
// adds to the indirect layer's variance. Each term is relMSE-weighted (1 / (ref^2 + 0.01)),
// averaged over pixels and RGB as
// image::relMse; bias includes the reference's own noise. Where the reference has direct and
// indirect layers (tools/merge_references.py of raw path-traced renders), the bias splits the
// same way, bias = direct + indirect + cross, each layer's error against the reference's layer
// with the combined image's weights, and each layer's reference noise from its spread. With
// a network, the same split of each seed's film denoised.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "app/args.h"
#include "bench/bench_scene.h"
#include "bench/benchmarks.h"
#include "bench/json.h"
#include "common/error.h"
#include "image/image_io.h"
#include "image/image_metrics.h"
#include "osr/osr_integrator.h"
#include "render/denoiser.h"

namespace osr::bench {

namespace {

// One layer over the seeds: per value, the relMSE weight (from the combined reference), the
// sum and the sum of squares, and the layer's own reference (`target`, or the combined one).
class SeedStats {
 public:
  SeedStats(const image::RgbImage& ref, const image::RgbImage* target = nullptr)
      : ref_(ref), target_(target ? *target : ref), sum_(ref.rgb.size()), sq_(ref.rgb.size()) {}
  void add(const std::vector<float>& x) {
    for (size_t i = 0; i < x.size(); ++i) sum_[i] += x[i], sq_[i] += double(x[i]) * x[i];
    ++n_;
  }
  // Over the values, relMSE-weighted: the mean unbiased sample variance over the seeds (noise)
  // and the seeds' mean's squared error less its share of that noise (bias).
  struct Split {
    double noise = 0.0, bias = 0.0;
  };
  Split split() const {
    double variance = 0.0, meanError = 0.0;
    for (size_t i = 0; i < sum_.size(); ++i) {
      const double d = sum_[i] / n_ - target_.rgb[i];
      variance += (sq_[i] - sum_[i] * sum_[i] / n_) / (n_ - 1) * weight(i);
      meanError += d * d * weight(i);
    }
    variance /= double(sum_.size());
    return {variance, meanError / double(sum_.size()) - variance / n_};
  }

 private:
  double weight(size_t i) const {
    return 1.0 / (double(ref_.rgb[i]) * ref_.rgb[i] + image::kRelMseEpsilon);
  }
  const image::RgbImage& ref_;
  const image::RgbImage& target_;
  std::vector<double> sum_, sq_;
  int n_ = 0;
};

}  // namespace

int runOsrError(const std::vector<std::string>& args) {
  app::Args a(args, "osr-error");
  const SceneArgs sceneArgs = readSceneArgs(a);
  const uint32_t size = uint32_t(a.integer("--size", 8, 4096).value_or(256));
  const auto budgetsArg = a.integerList("--budgets", 1, 3600);
  const auto passesArg = a.integerList("--passes", 1, 1 << 16);
  const int seeds = int(a.integer("--seeds", 2, 64).value_or(4));
  const uint32_t mapSpp = uint32_t(a.integer("--map-spp", 2, 1024).value_or(4));
  const std::string network = a.value("--network").value_or("default");
  a.finish();
  if (budgetsArg && passesArg) throw InputError("--budgets and --passes: give one of them");
  // Each point: a budget (its passes measured) or a pass count (budget 0).
  std::vector<std::pair<long long, uint32_t>> points;
  if (passesArg)
    for (long long p : *passesArg) points.push_back({0, uint32_t(p)});
  else
    for (long long b : budgetsArg.value_or(std::vector<long long>{5, 10, 30, 60})) points.push_back({b, 0});

  vk::Context ctx;
  const BenchScene bs(ctx, sceneArgs, size);
  const image::RgbImage& ref = bs.reference;
  // The reference's layers and their own noise, where it has them. A denoised render's layers
  // do not add up to its colour (the denoiser replaces only the colour): no split against it.
  const std::set<std::string> channels = image::exrChannels(sceneArgs.reference);
  const bool layered = channels.count("direct.R") && channels.count("indirect.R") && !channels.count("noisy.R");
  image::RgbImage refDirect, refIndirect;
  std::optional<double> refNoiseDirect, refNoiseIndirect;
  if (layered) {
    refDirect = image::readExrRgb(sceneArgs.reference, "direct");
    refIndirect = image::readExrRgb(sceneArgs.reference, "indirect");
    if (channels.count("direct.spread.R") && channels.count("indirect.spread.R")) {
      const auto spread = [&](const char* layer) { return image::readExrRgb(sceneArgs.reference, layer); };
      refNoiseDirect = image::referenceChannelNoise(ref, spread("direct.spread"));
      refNoiseIndirect = image::referenceChannelNoise(ref, spread("indirect.spread"));
    }
  }
  oneshot::OsrSettings settings;
  settings.resolveEverySubmission = false;  // as --offline
  oneshot::OsrIntegrator osr(ctx, *bs.gpu, *bs.bvh, size, size, settings);
  // Without the residual: the composite alone, its maps traced over the same map passes.
  settings.scheduleAs = oneshot::OsrSettings::ScheduleCosts{
      settings.pixelCost(settings.settlePasses), settings.pathsPerTexel};
  settings.residualSamples = settings.residualSamplesLate = 0;
  oneshot::OsrIntegrator mapsOnly(ctx, *bs.gpu, *bs.bvh, size, size, settings);
  settings.pathsPerTexel = mapSpp;
  oneshot::OsrIntegrator cleanMaps(ctx, *bs.gpu, *bs.bvh, size, size, settings);
  std::unique_ptr<render::Denoiser> net;
  if (network != "none") {
    render::DenoiseSettings ds = networkSettings(network);
    ds.atrous = true;  // as osr-vk: the filter where the network gives way to it
    net = std::make_unique<render::Denoiser>(ctx, ds, size, size);
  }
  render::RenderStats stats;
  renderFilm(ctx, osr, bs.camera, 1, 1, 0.0, stats);  // pipelines and first touches, untimed

  for (auto [budget, passes] : points) {
    if (budget) {
      renderFilm(ctx, osr, bs.camera, 1, 1u << 24, double(budget), stats);
      passes = std::max(1u, stats.units);
    }
    // The layers' noise does not depend on their reference; their bias is against its layers.
    SeedStats combined(ref), direct(ref, layered ? &refDirect : nullptr),
        indirect(ref, layered ? &refIndirect : nullptr), composite(ref), cleanComposite(ref),
        denoised(ref);
    double relSum = 0.0, denoisedRelSum = 0.0;
    for (int s = 0; s < seeds; ++s) {
      render::FilmLayers film = renderFilm(ctx, osr, bs.camera, uint32_t(s + 1), passes, 0.0, stats);
      relSum += image::relMse({int(size), int(size), film.combined}, ref) / seeds;
      combined.add(film.combined);
      direct.add(film.direct);
      indirect.add(film.indirect);
      if (net) {  // the same passes resolved with the blend osr-vk makes for a denoiser
        osr.setResidualNoiseWeight(oneshot::kDenoisedResidualNoiseWeight);
        render::FilmLayers forNet = osr.resolve();
        osr.setResidualNoiseWeight(1.0f);
        net->apply(forNet);
        denoisedRelSum += image::relMse({int(size), int(size), forNet.combined}, ref) / seeds;
        denoised.add(forNet.combined);
      }
      composite.add(renderFilm(ctx, mapsOnly, bs.camera, uint32_t(s + 1), passes, 0.0, stats).indirect);
      cleanComposite.add(
          renderFilm(ctx, cleanMaps, bs.camera, uint32_t(s + 1), passes, 0.0, stats).indirect);
    }
    const SeedStats::Split all = combined.split();
    const SeedStats::Split directSplit = direct.split(), indirectSplit = indirect.split();
    const double vDirect = directSplit.noise, vIndirect = indirectSplit.noise,
                 vComposite = composite.split().noise;
    const double maps = (vComposite - cleanComposite.split().noise) * mapSpp / (mapSpp - 1.0);
    JsonLine j;
    j.str("bench", "osr-error")
        .str("scene", sceneArgs.name)
        .str("reference", bs.referenceName)
        .integer("size", size)
        .integer("budget_s", budget)  // 0: --passes
        .integer("passes", passes)
        .integer("seeds", seeds)
        .num("relmse", relSum)
        .num("noise", all.noise)
        .num("bias", all.bias)
        .num("direct_noise", vDirect)
        .num("indirect_noise", vIndirect)
        .num("cross_noise", all.noise - vDirect - vIndirect)
        .num("maps_noise", maps)
        .num("placement_noise", vComposite - maps)
        .num("residual_noise", vIndirect - vComposite)
        .integer("map_spp", mapSpp);
    if (layered) {
      const double bDirect = directSplit.bias, bIndirect = indirectSplit.bias;
      j.num("direct_bias", bDirect).num("indirect_bias", bIndirect);
      j.num("cross_bias", all.bias - bDirect - bIndirect);
      if (refNoiseDirect) j.num("ref_noise_direct", *refNoiseDirect).num("ref_noise_indirect", *refNoiseIndirect);
    }
    if (net) {
      const SeedStats::Split after = denoised.split();
      j.str("network", network)
          .num("denoised_relmse", denoisedRelSum)
          .num("denoised_noise", after.noise)
          .num("denoised_bias", after.bias)
          .num("denoised_residual_noise_weight", oneshot::kDenoisedResidualNoiseWeight);
    }
    if (bs.referenceNoise) j.num("ref_noise", *bs.referenceNoise).str("ref_noise_from", bs.referenceNoiseFrom);  // part of both biases
    j.str("device", ctx.caps().deviceName).print();
  }
  return kExitOk;
}

}  // namespace osr::bench
