#include "app/integrators.h"

#include <algorithm>

#include "app/denoise_options.h"
#include "common/error.h"
#include "osr/osr_integrator.h"
#include "pt/path_integrator.h"

namespace osr::app {

namespace {

std::unique_ptr<render::Integrator> makePathTracer(const IntegratorScene& s,
                                                   const IntegratorSettings& settings,
                                                   uint32_t width, uint32_t height) {
  return std::make_unique<pt::PathIntegrator>(s.ctx, s.gpu, s.bvh, width, height,
                                              *pt::parseMode(settings.kind->name));
}

std::unique_ptr<render::Integrator> makeOsr(const IntegratorScene& s,
                                            const IntegratorSettings& settings, uint32_t width,
                                            uint32_t height) {
  oneshot::OsrSettings osr = settings.osr;
  osr.keepAllMaps = settings.keepAllMaps;
  osr.resolveEverySubmission = !settings.offline;
  return std::make_unique<oneshot::OsrIntegrator>(s.ctx, s.gpu, s.bvh, width, height, osr);
}

// Options valid in every mode (see EveryModeOptions).
EveryModeOptions readEveryModeOptions(Args& a, const std::string& mode) {
  EveryModeOptions o;
  o.denoise = readDenoiseOptions(a, mode);
  return o;
}

// The OSR settings of the options given; the defaults (OsrSettings) for the rest.
oneshot::OsrSettings osrSettings(const OsrOptions& o) {
  oneshot::OsrSettings s;
  if (o.denoiser) s.denoiser = oneshot::parseDenoiser(*o.denoiser);
  if (o.weights) {
    s.weightsPath = *o.weights;
    if (!o.denoiser) s.denoiser = oneshot::Denoiser::Unet;
  }
  if (o.gridStart) s.gridStart = uint32_t(*o.gridStart);
  if (o.gridMin)
    s.gridMin = uint32_t(*o.gridMin);
  else
    s.gridMin = std::min(s.gridMin, s.gridStart);
  // Given explicitly, a sample count holds for every pass.
  if (o.directSpp) s.directSamples = s.directSamplesLate = uint32_t(*o.directSpp);
  if (o.residualSpp) s.residualSamples = s.residualSamplesLate = uint32_t(*o.residualSpp);
  if (o.residualRamp) s.residualRamp = *o.residualRamp;
  if (o.residualGuide) s.residualGuide = float(*o.residualGuide);
  if (o.mapSpp) s.pathsPerTexel = uint32_t(*o.mapSpp);
  if (o.mapShare) s.mapShare = *o.mapShare;
  if (o.mapCache) s.mapCacheMaps = uint32_t(*o.mapCache);
  if (o.mapCacheReach) s.mapCacheMovedReach = float(*o.mapCacheReach);
  if (s.gridMin > s.gridStart)
    throw InputError("--grid-min: " + std::to_string(s.gridMin) + " is coarser than --grid-start " +
                     std::to_string(s.gridStart));
  return s;
}

}  // namespace

// Units: samples per pixel (path, preview) or passes (osr). Preview is deterministic after one
// sample per pixel but antialiases with more; OSR's defaults give a converged-looking image in
// about the path tracer's default time.
const std::vector<IntegratorKind>& integratorKinds() {
  static const std::vector<IntegratorKind> kinds = {
      {"path", "--spp", "sample per pixel", 64, false, makePathTracer},
      {"preview", "--spp", "sample per pixel", 4, false, makePathTracer},
      {"osr", "--passes", "pass", 32, true, makeOsr},
  };
  return kinds;
}

const IntegratorKind& integratorKind(const std::string& mode) {
  for (const IntegratorKind& k : integratorKinds())
    if (mode == k.name) return k;
  // The default first, then the rest in the registry's order.
  std::string known = kDefaultMode;
  for (const IntegratorKind& k : integratorKinds())
    if (std::string(k.name) != kDefaultMode) known += std::string(", ") + k.name;
  throw InputError("--mode: unknown integrator '" + mode + "' (" + known + ")");
}

std::string unitOptionsHelp() {
  // One line per unit option, naming the kinds it counts for, the first one's default and
  // each other kind's where it differs: the defaults are the registry's, written once.
  const std::vector<std::pair<std::string, std::string>> meaning = {
      {"--spp", "samples per pixel"}, {"--passes", "progressive passes"}};
  std::string help;
  for (const auto& [option, what] : meaning) {
    std::string names, defaults;
    const IntegratorKind* first = nullptr;
    for (const IntegratorKind& k : integratorKinds()) {
      if (option != k.unitOption) continue;
      names += std::string(names.empty() ? "" : ", ") + k.name;
      if (!first) {
        first = &k;
        defaults = "default " + std::to_string(k.defaultUnits);
      } else if (k.defaultUnits != first->defaultUnits) {
        defaults += std::string("; ") + k.name + " " + std::to_string(k.defaultUnits);
      }
    }
    std::string flag = "  " + option + " N";
    flag.resize(24, ' ');
    help += flag + names + ": " + what + " (" + defaults + ")\n";
  }
  return help;
}

std::vector<std::string> integratorNames() {
  std::vector<std::string> names;
  for (const IntegratorKind& k : integratorKinds()) names.push_back(k.name);
  return names;
}

bool OsrOptions::any() const {
  return passes || denoiser || weights || gridStart || gridMin || directSpp || residualSpp ||
         residualRamp || residualGuide || mapSpp || mapShare || mapCache || mapCacheReach;
}

IntegratorOptions readIntegratorOptions(Args& a) {
  IntegratorOptions o;
  o.mode = a.value("--mode").value_or(kDefaultMode);
  o.everyMode = readEveryModeOptions(a, o.mode);
  o.pt.spp = a.integer("--spp", 1, 1 << 24);
  o.osr.passes = a.integer("--passes", 1, 1 << 24);
  o.osr.denoiser = a.value("--denoiser");
  o.osr.weights = a.value("--weights");
  o.osr.gridStart = a.integer("--grid-start", 1, 256);
  o.osr.gridMin = a.integer("--grid-min", 1, 256);
  o.osr.directSpp = a.integer("--direct-spp", 1, 1024);
  o.osr.residualSpp = a.integer("--residual-spp", 0, 1024);
  o.osr.residualRamp = a.number("--residual-ramp", 0.0, 1e9);
  o.osr.residualGuide = a.number("--residual-guide", 0.0, 0.95);
  o.osr.mapSpp = a.integer("--map-spp", 1, 1 << 16);
  o.osr.mapShare = a.number("--map-share", 0.0, 1.0);
  o.osr.mapCache = a.integer("--map-cache", 0, 1 << 20);
  o.osr.mapCacheReach = a.number("--map-cache-reach", 0.0, 1e6);
  return o;
}

IntegratorSettings buildIntegratorSettings(const IntegratorOptions& o) {
  IntegratorSettings s;
  s.kind = &integratorKind(o.mode);
  const bool osrMode = o.mode == "osr";
  // An option of another mode would be ignored without a word: refused.
  if (!osrMode && o.osr.any())
    throw InputError(
        "render: --passes, --denoiser, --weights, --grid-*, --direct-spp, "
        "--residual-*, --map-spp, --map-share, --map-cache* are options of --mode osr");
  if (osrMode && o.pt.any())
    throw InputError("--spp: --mode osr counts progressive passes; use --passes N");
  const std::optional<long long> units = osrMode ? o.osr.passes : o.pt.spp;
  if (units) s.units = uint32_t(*units);
  s.everyMode = o.everyMode;
  s.osr = osrSettings(o.osr);
  // OSR blends in more of its residual for an image denoiser (docs/osr.md, "Blending the
  // residual in"); the offline renderer sets it again once --time has settled the denoiser.
  s.osr.residualNoiseWeight = oneshot::residualNoiseWeightFor(s.everyMode.denoise.active());
  return s;
}

std::unique_ptr<render::Integrator> makeIntegrator(const IntegratorScene& scene,
                                                   const IntegratorSettings& settings,
                                                   const std::string& mode, uint32_t width,
                                                   uint32_t height) {
  IntegratorSettings chosen = settings;
  chosen.kind = &integratorKind(mode);
  return chosen.kind->make(scene, chosen, width, height);
}

viewer::IntegratorFactory viewerFactory(const IntegratorScene& scene,
                                        const IntegratorSettings& settings) {
  return [scene, settings](const std::string& mode, uint32_t width, uint32_t height) {
    viewer::IntegratorChoice c;
    c.integrator = makeIntegrator(scene, settings, mode, width, height);
    c.defaultUnits = integratorKind(mode).defaultUnits;
    return c;
  };
}

}  // namespace osr::app
