// The integrator registry: every integrator osr-vk runs (path, preview, osr), with its name,
// the option that counts its units and their default, which options belong to it, and how its
// settings are built from the command line. The CLI (cmd_render.cpp) and the benchmarks
// (bench/) make their integrators here, and the viewer switches between the ones listed here
// through the mode list and factory its ViewerConfig carries, so a rule such as "--weights
// implies --denoiser unet" or a default unit count is written once. It lives in src/app, not in
// a library of its own: it names every integrator, so it must sit above osr and pt (DESIGN.md),
// and it reads app::Args; osr-bench links osr_app already, and the viewer (below app) takes the
// list and factory through ViewerConfig rather than including this header.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/args.h"
#include "bvh/bvh.h"
#include "osr/osr_settings.h"
#include "render/denoiser.h"
#include "render/integrator.h"
#include "scene_gpu/gpu_scene.h"
#include "viewer/viewer.h"
#include "vk/context.h"

namespace osr::app {

struct IntegratorScene;
struct IntegratorSettings;

// One integrator the registry makes.
struct IntegratorKind {
  const char* name;        // as --mode and the viewer's list spell it
  const char* unitOption;  // the option that counts its units
  const char* oneUnit;     // one unit in words ("pass"), for messages
  uint32_t defaultUnits;   // units without a count or --time
  // Whether a unit that --time or Ctrl-C stopped part-way is dropped from the image (after a
  // complete one; Integrator::abandonUnit does it) rather than kept where it reached.
  bool dropsPartialUnit;
  std::unique_ptr<render::Integrator> (*make)(const IntegratorScene& scene,
                                              const IntegratorSettings& settings,
                                              uint32_t width, uint32_t height);
};
// path, preview, osr: the viewer's order.
const std::vector<IntegratorKind>& integratorKinds();
// Path tracing with the learned denoiser gives the lowest relMSE at equal time on cornell, room
// and held-out generated interiors; OSR with it is 1.5-5.2x worse (docs/osr.md, "Against path
// tracing once both are denoised").
inline constexpr char kDefaultMode[] = "path";
// The kind named `mode`; InputError naming --mode and the known kinds otherwise.
const IntegratorKind& integratorKind(const std::string& mode);
std::vector<std::string> integratorNames();
// The --spp and --passes lines of osr-vk --help, with the registry's defaults.
std::string unitOptionsHelp();

// Options valid in every mode. To add one: a field here and one line reading it in
// readEveryModeOptions (integrators.cpp); makeIntegrator hands it to every kind it makes.
struct EveryModeOptions {
  render::DenoiseSettings denoise;  // --network, --filter, or the mode's default (docs/denoise.md)
};

// Options of --mode path and preview, as given.
struct PtOptions {
  std::optional<long long> spp;
  bool any() const { return bool(spp); }
};

// Options of --mode osr, as given.
struct OsrOptions {
  std::optional<long long> passes;
  std::optional<std::string> denoiser, weights;
  std::optional<long long> gridStart, gridMin, directSpp, residualSpp, mapSpp, mapCache;
  std::optional<double> residualRamp, residualGuide, mapShare, mapCacheReach;
  bool any() const;
};

// Every integrator option of `osr-vk render`, as given (unchecked).
struct IntegratorOptions {
  std::string mode = kDefaultMode;
  EveryModeOptions everyMode;
  PtOptions pt;
  OsrOptions osr;
};
// Consumes --mode and every mode's options from `args`.
IntegratorOptions readIntegratorOptions(Args& args);

// The chosen kind and its settings, checked: what makeIntegrator needs besides the film size.
struct IntegratorSettings {
  const IntegratorKind* kind = nullptr;
  std::optional<uint32_t> units;  // --spp / --passes as given; empty: the kind's default
  EveryModeOptions everyMode;
  oneshot::OsrSettings osr;       // --mode osr
  // Nothing shows the film before the end (--offline, benchmarks): the OSR resolve runs once.
  bool offline = false;
  bool keepAllMaps = false;       // --dump-maps: every map of a pass kept for download
  uint32_t unitsOrDefault() const { return units.value_or(kind->defaultUnits); }
};
// InputError on an unknown mode, an option of another mode, or inconsistent values.
IntegratorSettings buildIntegratorSettings(const IntegratorOptions& options);

// The device scene every integrator renders; it outlives them.
struct IntegratorScene {
  const vk::Context& ctx;
  const scene::GpuScene& gpu;
  const bvh::Bvh& bvh;
};
// A new integrator of `mode` (a name of integratorKinds()) for a width x height film.
std::unique_ptr<render::Integrator> makeIntegrator(const IntegratorScene& scene,
                                                   const IntegratorSettings& settings,
                                                   const std::string& mode, uint32_t width,
                                                   uint32_t height);
// The viewer's factory: makeIntegrator with the kind's default units.
viewer::IntegratorFactory viewerFactory(const IntegratorScene& scene,
                                        const IntegratorSettings& settings);

}  // namespace osr::app
