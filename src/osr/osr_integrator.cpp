#include "osr/osr_integrator.h"

#include <algorithm>

#include "common/error.h"
#include "nn_kernels/weights_format.h"
#include "osr/default_model.h"
#include "render/camera_frame.h"
#include "vk/timer.h"

namespace osr::oneshot {

namespace o = gpu::osr;

Denoiser parseDenoiser(const std::string& name) {
  if (name == "unet") return Denoiser::Unet;
  if (name == "blur") return Denoiser::Blur;
  if (name == "none") return Denoiser::None;
  throw InputError("--denoiser: unknown denoiser '" + name + "' (unet, blur, none)");
}

const char* denoiserName(Denoiser d) {
  switch (d) {
    case Denoiser::Unet:
      return "unet";
    case Denoiser::Blur:
      return "blur";
    case Denoiser::None:
      return "none";
  }
  return "?";
}

namespace {

// The network, and how its output becomes radiance (netOutput: o::kNetOutput*).
std::unique_ptr<nn::UNet> loadNetwork(const vk::Context& ctx, const OsrSettings& s,
                                      uint32_t& netOutput) {
  if (s.denoiser != Denoiser::Unet) return nullptr;
  if (s.weightsPath.empty() && defaultModelBytes().empty())
    throw InputError(
        "--denoiser unet: this build has no built-in model (models/osr_unet.osrw); give "
        "--weights FILE (tools/weights_pack.py) or use --denoiser blur");
  nn::UNetWeights w = s.weightsPath.empty()
                          ? nn::UNetWeights::parse(defaultModelBytes(), kDefaultModelName)
                          : nn::UNetWeights::load(s.weightsPath);
  // The maps fed to it are cosine-concentric and normalized per DESIGN.md (shared/osr.h).
  const bool absolute = w.normalization == nn::kNormalizationLogMean10Absolute;
  w.requireConventions(nn::kMappingConcentric, absolute ? nn::kNormalizationLogMean10Absolute
                                                        : nn::kNormalizationLogMean10);
  netOutput = absolute ? o::kNetOutputAbsolute : o::kNetOutputRescaled;
  return std::make_unique<nn::UNet>(ctx, w);
}

// The layout of the passes over whole maps (lib/osr_map_group.glsl).
bool mapPassesByGroup(const vk::Context& ctx, const OsrSettings& s) {
  return s.mapPassesByGroup.value_or(!ctx.caps().isCpu());
}

}  // namespace

OsrIntegrator::OsrIntegrator(const vk::Context& ctx, const scene::GpuScene& scene,
                             const bvh::Bvh& bvh, uint32_t width, uint32_t height,
                             const OsrSettings& settings)
    : ctx_(ctx),
      scene_(&scene),
      bvh_(&bvh),
      sceneFeatures_(scene.features),
      sceneTexelFetch_(scene.texelFetch),
      width_(width),
      height_(height),
      settings_(settings),
      schedule_(width, height, settings.gridStart, settings.gridMin, settings.mapShare,
                // The late passes' per-pixel work: what the map share is measured against.
                settings.scheduleAs ? settings.scheduleAs->pixelCost
                                    : settings.pixelCost(settings.settlePasses),
                settings.scheduleAs ? settings.scheduleAs->texelPaths : settings.pathsPerTexel),
      film_(ctx, width, height),
      unet_(loadNetwork(ctx, settings, netOutput_)),
      gbuffer_(ctx, scene.features, scene.texelFetch),
      direct_(ctx, scene.features, scene.texelFetch),
      maps_(ctx, scene.features, scene.texelFetch),
      normalize_(ctx, scene.features, scene.texelFetch, mapPassesByGroup(ctx, settings)),
      denoise_(ctx, scene.features, scene.texelFetch, uint32_t(settings.denoiser), netOutput_,
               mapPassesByGroup(ctx, settings)),
      project_(ctx, scene.features, scene.texelFetch, mapPassesByGroup(ctx, settings)),
      cacheLookup_(ctx, scene.features, scene.texelFetch),
      cacheClaim_(ctx, scene.features, scene.texelFetch),
      cacheStore_(ctx, scene.features, scene.texelFetch),
      cache_(std::make_unique<MapCache>(ctx, std::max(settings.mapCacheMaps, o::kMapCacheWays))),
      composite_(ctx, scene.features, scene.texelFetch),
      residual_(ctx, scene.features, scene.texelFetch),
      resolve_(ctx, scene.features, scene.texelFetch) {
  const uint32_t maxMaps = schedule_.maxMaps();
  const uint32_t chunk = settings.keepAllMaps ? maxMaps : settings.maxChunkMaps;
  buffers_ = std::make_unique<OsrBuffers>(ctx, width, height, maxMaps, chunk);
  bindings_ = OsrBindings{buffers_.get(), &film_, bvh_, scene_, cache_.get()};
  // Without a cache every point stays traced (OsrBuffers starts them so) and no cache pass runs.
  preparePasses();
}

OsrIntegrator::~OsrIntegrator() = default;

void OsrIntegrator::preparePasses() {
  gbuffer_.prepare(*bvh_);
  direct_.prepare(*bvh_);
  maps_.prepare(*bvh_);
  normalize_.prepare(*bvh_);
  denoise_.prepare(*bvh_);
  project_.prepare(*bvh_);
  if (settings_.mapCacheMaps) {
    cacheLookup_.prepare(*bvh_);
    cacheClaim_.prepare(*bvh_);
    cacheStore_.prepare(*bvh_);
  }
  composite_.prepare(*bvh_);
  residual_.prepare(*bvh_);
  resolve_.prepare(*bvh_);
}

bool OsrIntegrator::rebind(const scene::GpuScene& scene, const bvh::Bvh& bvh,
                           const scene::PoseChange& change) {
  if (scene.features != sceneFeatures_ || scene.texelFetch != sceneTexelFetch_) return false;
  scene_ = &scene;
  bvh_ = &bvh;
  bindings_.scene = scene_;
  bindings_.bvh = bvh_;
  preparePasses();  // a BVH of another node format needs its own pipelines
  invalidateMoved(change);
  return true;
}

MapCache::Invalidated OsrIntegrator::invalidateMoved(const scene::PoseChange& change) {
  if (!settings_.mapCacheMaps) return {};
  bool lightMoved = change.lightMoved;
  std::vector<MapCacheRegion> regions;
  for (const scene::MovedPrimitive& m : change.moved) {
    lightMoved = lightMoved || m.emissive;
    for (const auto& [lo, hi] :
         {std::pair(m.beforeLo, m.beforeHi), std::pair(m.afterLo, m.afterHi)})
      regions.push_back({lo, hi, settings_.mapCacheMovedReach * glm::length(hi - lo)});
  }
  if (lightMoved) {
    MapCache::Invalidated all;
    all.stale = cache_->liveMaps();
    cache_->invalidate();
    return all;
  }
  if (regions.empty()) return {0, cache_->liveMaps()};
  return cache_->invalidateNear(regions, settings_.mapCacheCellScale);
}

double OsrIntegrator::unitCost(uint32_t pass) const {
  const GridPass p = schedule_.pass(pass);
  const double pixelWork = settings_.pixelCost(pass) * double(width_) * height_;
  return pixelWork + schedule_.mapWork(p);
}

OsrIntegrator::Grid OsrIntegrator::gridOf(uint32_t radius, uint32_t mapPass) const {
  Grid g{};
  g.radius = radius;
  const glm::uvec2 cells = schedule_.cellsOfRadius(radius);
  g.cellsX = cells.x;
  g.cellsY = cells.y;
  g.seed = seed_ * 0x9e3779b9u + mapPass * 0x85ebca6bu + 0x27d4eb2fu;
  return g;
}

void OsrIntegrator::restart(const scene::Camera& camera, uint32_t seed) {
  seed_ = seed;
  current_ = Grid{};
  mapsTraced_ = 0;
  passesDone_ = 0;
  filmBehind_ = false;
  resolvePixels_ = width_ * height_;
  reachedPixels_ = 0;
  auto frame = render::makeFrame(camera, width_, height_, seed);
  buffers_->frame.upload(&frame, sizeof frame);
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, buffers_->accum.handle(), 0, VK_WHOLE_SIZE, 0u);
    film_.recordClear(cmd);
  });
}

void OsrIntegrator::beginPass(uint32_t k) {
  const GridPass gp = schedule_.pass(k);
  if (!gp.traceMaps) return;
  current_ = gridOf(gp.radius, gp.mapPass);
  currentMapPass_ = gp.mapPass;
  if (settings_.mapCacheMaps) cacheClock_ = cache_->tick();
  mapsTraced_ += current_.cellsX * current_.cellsY;
}

std::vector<OsrIntegrator::Step> OsrIntegrator::stepsOfPass(uint32_t k, uint32_t bands,
                                                            uint32_t chunkMaps) const {
  using K = Step::Kind;
  const GridPass gp = schedule_.pass(k);
  const PassSamples samples = settings_.samplesOfPass(k);
  const uint32_t pixels = width_ * height_;
  std::vector<Step> steps;
  // Per-pixel costs in path units (as OsrSettings::pixelCost splits them).
  auto banded = [&](std::vector<Step>& out, K kind, double perPixel) {
    if (perPixel <= 0.0) return;
    for (uint32_t b = 0; b < bands; ++b) {
      // Band edges on window-aligned pixels (OsrPass binds from there).
      auto edge = [&](uint32_t i) {
        return i == bands ? pixels
                          : uint32_t(uint64_t(pixels) * i / bands) / render::kWindowAlignPixels *
                                render::kWindowAlignPixels;
      };
      if (edge(b + 1) > edge(b)) out.push_back({kind, edge(b), edge(b + 1), perPixel * (edge(b + 1) - edge(b))});
    }
  };
  banded(steps, K::Gbuffer, settings_.gbufferCost(k));
  if (gp.traceMaps) {
    const uint32_t maps = current_.cellsX * current_.cellsY;
    const double perMap = schedule_.mapWork(gp) / std::max(maps, 1u);
    for (uint32_t first = 0; first < maps; first += chunkMaps)
      steps.push_back({K::Maps, first, std::min(maps, first + chunkMaps),
                       perMap * (std::min(maps, first + chunkMaps) - first)});
  }
  // Direct light and the maps' indirect light band by band, so that the bands the viewer shows
  // during a first pass are lit by both (with the map cache the maps come at once).
  std::vector<Step> direct, composite;
  banded(direct, K::Direct, 0.5 * samples.direct);
  banded(composite, K::Composite, 0.25);
  for (size_t b = 0; b < std::max(direct.size(), composite.size()); ++b) {
    if (b < direct.size()) steps.push_back(direct[b]);
    if (b < composite.size()) steps.push_back(composite[b]);
  }
  banded(steps, K::Residual, double(samples.residual));
  return steps;
}

void OsrIntegrator::recordStep(VkCommandBuffer cmd, uint32_t k, const Step& step,
                               vk::GpuTimer* timer) {
  using K = Step::Kind;
  const PassSamples samples = settings_.samplesOfPass(k);
  const PixelRange pixels{step.begin, step.end};
  const float weight = schedule_.pass(k).weight;
  switch (step.kind) {
    case K::Gbuffer: {
      vk::TimedScope scope(timer, cmd, "gbuffer");
      // The direct layer weighs each pass by its light samples (osr_direct does the same).
      gbuffer_.record(cmd, bindings_,
                      {k, samples.camera, float(std::max(samples.direct, 1u)), pixels});
      break;
    }
    case K::Direct: {
      vk::TimedScope scope(timer, cmd, "direct");
      direct_.record(cmd, bindings_, k, samples.direct, pixels);
      break;
    }
    case K::Maps: {
      const MapChunk chunk{step.begin, step.end - step.begin};
      const MapCacheArgs cache{current_,        chunk,           cache_->sets(),
                               cache_->generation(), cacheClock_, currentMapPass_,
                               settings_.mapCacheCellScale, settings_.mapCacheMaturePasses};
      if (settings_.mapCacheMaps) {
        vk::TimedScope scope(timer, cmd, "cache lookup");
        cacheLookup_.record(cmd, bindings_, cache);
      }
      {
        vk::TimedScope scope(timer, cmd, "maps");
        maps_.record(cmd, bindings_, {current_, k, chunk, settings_.pathsPerTexel});
      }
      {
        // Every denoiser needs the per-map statistics; only the U-Net its normalized input.
        vk::TimedScope scope(timer, cmd, "normalize");
        normalize_.record(cmd, bindings_, chunk);
      }
      if (unet_) {
        vk::TimedScope scope(timer, cmd, "unet");
        unet_->record(cmd, buffers_->netIn, 0, buffers_->netOut, 0, chunk.count);
      }
      {
        vk::TimedScope scope(timer, cmd, "denoise");
        denoise_.record(cmd, bindings_, chunk);
      }
      if (settings_.mapCacheMaps) {
        vk::TimedScope scope(timer, cmd, "cache store");
        cacheClaim_.record(cmd, bindings_, cache);
        cacheStore_.record(cmd, bindings_, cache);
      }
      vk::TimedScope scope(timer, cmd, "project");
      project_.record(cmd, bindings_, chunk);
      break;
    }
    case K::Composite: {
      vk::TimedScope scope(timer, cmd, "composite");
      composite_.record(cmd, bindings_,
                        {current_, k, settings_.glossySamples, weight, pixels,
                         schedule_.pass(k).traceMaps ? weight : 0.f});
      break;
    }
    case K::Residual: {
      vk::TimedScope scope(timer, cmd, "residual");
      residual_.record(cmd, bindings_,
                       {current_, k, samples.residual, weight, pixels, 0.f, settings_.residualGuide});
      break;
    }
  }
}

void OsrIntegrator::recordResolve(VkCommandBuffer cmd, uint32_t passesDone,
                                  vk::GpuTimer* timer) const {
  // Negative: the resolve measures each pixel's blend (docs/osr.md). Else the fixed ramp, by
  // passes, not samples: the late passes' extra residual paths lower its noise instead of
  // showing it sooner.
  float residualBlend = -1.0f;
  if (settings_.residualRamp >= 0.0) {
    const double n = settings_.samplesOfPass(0).residual > 0 ? double(passesDone) : 0.0;
    residualBlend = settings_.residualRamp > 0.0 ? float(n / (n + settings_.residualRamp))
                                                 : (n > 0.0 ? 1.f : 0.f);
  }
  if (resolvePixels_ == 0) return;  // an abandoned first pass that reached no pixel: all black
  vk::TimedScope scope(timer, cmd, "resolve");
  resolve_.record(cmd, bindings_, residualBlend, settings_.residualNoiseWeight, {0, resolvePixels_});
}

void OsrIntegrator::record(VkCommandBuffer cmd, uint32_t first, uint32_t count,
                           vk::GpuTimer* timer) {
  for (uint32_t k = first; k < first + count; ++k) {
    beginPass(k);
    for (const Step& step : stepsOfPass(k, 1, buffers_->chunkMaps)) recordStep(cmd, k, step, timer);
  }
  passesDone_ = first + count;
  filmBehind_ = !settings_.resolveEverySubmission;
  if (!filmBehind_) recordResolve(cmd, passesDone_, timer);
}

void OsrIntegrator::setResidualNoiseWeight(float weight) {
  settings_.residualNoiseWeight = weight;
  if (passesDone_ > 0) filmBehind_ = true;
}

void OsrIntegrator::resolveInto(render::FilmLayers& into) const {
  if (filmBehind_) {
    ctx_.submitAndWait([&](VkCommandBuffer cmd) { recordResolve(cmd, passesDone_, nullptr); });
    filmBehind_ = false;
  }
  film_.resolve(into);
  // One sample's worth per pixel in the layers (their variance is the estimate's, osr_resolve),
  // but the noise of passesDone_ passes, each of 4 or more direct samples and residual paths:
  // what the denoisers' choice of network or filter goes by (kNetworkMinSamples).
  into.samples = passesDone_;
}

void OsrIntegrator::recordSlice(VkCommandBuffer cmd, uint32_t unit, uint32_t slice,
                                uint32_t slices, vk::GpuTimer* timer) {
  if (slice == 0) {
    // The film is resolved for the passes before this one, so that it can be dropped when
    // the driver stops part-way (abandonUnit): one pixel pass per sliced pass.
    if (filmBehind_ && unit > 0) recordResolve(cmd, unit, timer);
    filmBehind_ = false;
    beginPass(unit);
  }
  const uint32_t maps = current_.cellsX * current_.cellsY;
  // At least 16 maps a chunk: smaller ones cost more in dispatches and barriers than they
  // save in submission length (about 30 ms of map paths on lavapipe). keepAllMaps keeps the
  // one chunk of all maps, which downloadMaps reads.
  const uint32_t chunk =
      settings_.keepAllMaps ? buffers_->chunkMaps
                            : std::clamp((maps + slices - 1) / slices, std::min(16u, buffers_->chunkMaps),
                                         buffers_->chunkMaps);
  const std::vector<Step> steps = stepsOfPass(unit, slices, chunk);
  double total = 0.0;
  for (const Step& s : steps) total += s.cost;
  // A step belongs to the slice its cost midpoint falls in: every slice call sees the same
  // steps, so each step is recorded exactly once, in order.
  double before = 0.0;
  for (const Step& s : steps) {
    const double mid = total > 0.0 ? (before + 0.5 * s.cost) / total : 0.0;
    before += s.cost;
    if (std::min(uint32_t(mid * slices), slices - 1) != slice) continue;
    recordStep(cmd, unit, s, timer);
    if (s.kind != Step::Kind::Maps) reachedPixels_ = std::max(reachedPixels_, s.end);
  }
  if (slice + 1 == slices) passesDone_ = unit + 1;
  if (!settings_.resolveEverySubmission) {  // nothing shows the film before the end (the CLI)
    filmBehind_ = true;
    return;
  }
  // The film shows the last resolved image; during the first pass after a restart there is
  // none, so the viewer would show black for a whole pass: resolve what is there (direct
  // light first, then the indirect band by band) every sixteenth of it.
  const bool firstPassPreview = unit == 0 && (slice + 1) % std::max(1u, slices / 16) == 0;
  filmBehind_ = false;
  if (slice + 1 == slices) {
    recordResolve(cmd, unit + 1, timer);
  } else if (firstPassPreview) {
    recordResolve(cmd, unit, timer);
  }
}

std::vector<o::MapCacheRef> OsrIntegrator::mapCacheRefs() const {
  return buffers_->mapCacheRefs.downloadVector<o::MapCacheRef>(current_.cellsX * current_.cellsY);
}

std::array<uint32_t, 4> OsrIntegrator::mapCacheActions() const {
  std::array<uint32_t, 4> counts{};
  for (const o::MapCacheRef& r : mapCacheRefs())
    if (r.action < counts.size()) ++counts[r.action];
  return counts;
}

void OsrIntegrator::abandonUnit(uint32_t unit, uint32_t /*slicesDone*/, uint32_t /*slices*/) {
  passesDone_ = unit;
  // After complete passes the film already holds them; the first pass is resolved as it is,
  // over the pixels its bands reached: restart() cleared the film, so the rest stays black,
  // and the resolve of a 4K image reached for a few percent costs seconds on lavapipe.
  filmBehind_ = unit == 0;
  if (unit == 0) resolvePixels_ = reachedPixels_;
}

OsrIntegrator::MapDump OsrIntegrator::downloadMaps() const {
  MapDump d;
  d.maps = current_.cellsX * current_.cellsY;
  d.cellsX = current_.cellsX;
  d.cellsY = current_.cellsY;
  d.radius = current_.radius;
  const size_t texels = gpu::hemi::kMapTexels;
  d.clean = buffers_->mapClean.downloadVector<float>(size_t(d.maps) * 3 * texels);
  d.points = buffers_->mapPoints.downloadVector<o::MapPoint>(d.maps);
  d.projections = buffers_->mapProjections.downloadVector<o::MapProjection>(d.maps);
  if (buffers_->chunkMaps >= d.maps)
    d.oneShot = buffers_->oneShot.downloadVector<float>(size_t(d.maps) * o::kMapChannels * texels);
  return d;
}

}  // namespace osr::oneshot
