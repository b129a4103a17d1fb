// What the OSR integrator is asked to do (src/osr/osr_integrator.h); the CLI fills it from
// --denoiser, --weights, --grid-start, --grid-min and friends.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "shaders/shared/osr.h"

namespace osr::oneshot {

enum class Denoiser : uint32_t {
  Unet = gpu::osr::kDenoiserUnet,  // the packed U-Net of `weightsPath`
  Blur = gpu::osr::kDenoiserBlur,  // a fixed Gaussian blur of the one-shot map
  None = gpu::osr::kDenoiserNone,  // the raw one-shot map
};
// "unet" | "blur" | "none"; throws InputError naming --denoiser otherwise.
Denoiser parseDenoiser(const std::string& name);
const char* denoiserName(Denoiser d);

struct PassSamples {
  uint32_t direct, residual;
  uint32_t camera;  // camera rays per pixel for the emission seen directly (osr_gbuffer)
};

// The map cache's size where it is on by default (the viewer, --frames): 48 MiB of maps, four
// times the maps of a 512 x 512 pass at the default grid.
inline constexpr uint32_t kDefaultMapCacheMaps = 4096;
// OsrSettings::mapCacheMaturePasses of a shot (--frames).
inline constexpr uint32_t kShotMatureMapPasses = 8;
// OsrSettings::mapCacheMovedReach (docs/osr.md "Eviction and invalidation").
inline constexpr float kMapCacheMovedReach = 1.0f;

// Light passes after each restart in the viewer (OsrSettings::quickPasses).
inline constexpr uint32_t kViewerQuickPasses = 1;
// OsrSettings::residualNoiseWeight where an image denoiser follows: with the network, 0.75x
// the error of 1 on cornell, 0.85-0.89x on room, 1.00x on interior 9002 (docs/osr.md).
inline constexpr float kDenoisedResidualNoiseWeight = 0.5f;
inline float residualNoiseWeightFor(bool imageDenoised) {
  return imageDenoised ? kDenoisedResidualNoiseWeight : 1.0f;
}

struct OsrSettings {
  // Measured (docs/training.md): at equal time the shipped U-Net's better maps do not yet pay
  // for its cost per pass on lavapipe (better on room at 10 s, worse on cornell and at 30 s),
  // so the blur is the default; Unet without weightsPath runs the built-in model.
  Denoiser denoiser = Denoiser::Blur;
  std::string weightsPath;       // packed U-Net (tools/weights_pack.py); empty: the built-in one
  uint32_t gridStart = 16;       // grid spacing r of the first pass, pixels
  uint32_t gridMin = 16;         // finest spacing the schedule refines to
  double mapShare = 0.25;        // largest share of the work map passes may take
  uint32_t pathsPerTexel = 1;    // paths per map texel (1: the one-shot maps of DESIGN.md)
  // The grid schedule's map passes as for this per-pixel work and these paths per texel,
  // whatever the settings' own: osr-bench osr-error compares variants (no residual, more paths
  // per texel) over the default's map passes. Unset: the settings' own.
  struct ScheduleCosts {
    double pixelCost;
    uint32_t texelPaths;
  };
  std::optional<ScheduleCosts> scheduleAs;
  // Samples per pixel per pass. The first `settlePasses` passes favour a clean first image
  // (many light samples, one residual path); later ones shift the work to the residual.
  uint32_t directSamples = 16;       // light samples, first passes
  uint32_t residualSamples = 1;      // residual paths, first passes (0: maps only, biased)
  uint32_t directSamplesLate = 4;    // light samples from pass settlePasses on
  uint32_t residualSamplesLate = 4;  // residual paths from pass settlePasses on
  // Camera rays per pixel and pass for the lights seen directly: one sample a pass leaves a
  // light's edge pixels speckled for many passes (the pixel filter reaches 1 px past them).
  uint32_t cameraSamples = 8;        // first passes
  uint32_t cameraSamplesLate = 1;    // from pass settlePasses on (the G-buffer ray alone)
  uint32_t settlePasses = 8;
  uint32_t glossySamples = 4;    // map lookups per pixel for wide glossy lobes
  // Probability that a residual path's first direction is drawn from the maps around the
  // pixel (by their texels' luminance) instead of its BSDF, where the BSDF is diffuse
  // (scaled by the diffuse lobe's share); 0: the BSDF's alone (docs/osr.md "Guided residual").
  float residualGuide = 0.0f;
  // How the residual is blended in: < 0 (default) per pixel by the measured shrinkage of
  // shared/osr.h residualShrinkBlend; n0 >= 0 a fixed ramp k / (k + n0) after k passes.
  double residualRamp = -1.0;
  // The residual's variance against the maps' error in that measured blend: 1 for an image
  // shown as it is; kDenoisedResidualNoiseWeight for one an image denoiser cleans, which
  // removes much of the residual's noise and none of the maps' error, so more of the residual
  // pays (docs/osr.md "Blending the residual in").
  float residualNoiseWeight = 1.0f;
  // The world-space map cache (docs/osr.md "The map cache"): room for this many maps (12 KiB
  // each on the device); 0: none, every pass traces all its maps. It outlives restart(), so
  // camera moves (the viewer) and camera-only animations (--frames) reuse it.
  uint32_t mapCacheMaps = 0;
  // Side of the cache's world cells in grid spacings at the point (rounded up to 2^k).
  float mapCacheCellScale = 0.5f;
  // A cached map is reused untraced only once it averages this many map passes; until then
  // every restart that sees it traces it again and averages it in. 0: reused as soon as it
  // averages more map passes than the restart has made (the viewer: the first image after a
  // move comes at once). A shot's frames set kShotMatureMapPasses: each frame makes few map
  // passes, so without a floor its maps would stay as noisy as one frame's (docs/animation.md
  // "Temporal quality").
  uint32_t mapCacheMaturePasses = 0;
  // After an object moves (a shot's frame, OsrIntegrator::invalidateMoved), the cached maps
  // within this many times its bounds' diagonal of its bounds before or after are stale.
  float mapCacheMovedReach = kMapCacheMovedReach;
  uint32_t maxChunkMaps = 512;   // maps traced and denoised per chunk (memory bound)
  bool keepAllMaps = false;      // one chunk for all maps of a pass (for --dump-maps)
  // The layout of the passes over whole maps (normalize, denoise, project;
  // lib/osr_map_group.glsl): a workgroup per map, or an invocation per map; unset: by group
  // on a GPU, by map on a CPU device.
  std::optional<bool> mapPassesByGroup;
  // Resolve the film after every submission (a front end that shows it, the viewer); false:
  // only when resolve() downloads it (offline: the resolve's 9 x 9 blend costs about 5% of
  // a 256 x 256 pass on lavapipe).
  bool resolveEverySubmission = true;

  // Passes after a restart that take few samples, so that an image is on screen soon after a
  // camera move (the viewer; docs/viewer.md): the late passes' light samples, the first
  // passes' residual paths, quickCameraSamples camera rays. 0: none (offline renders start with the settle passes).
  uint32_t quickPasses = 0;
  uint32_t quickCameraSamples = 2;

  PassSamples samplesOfPass(uint32_t pass) const {
    if (pass < quickPasses)
      return PassSamples{directSamplesLate, residualSamples, quickCameraSamples};
    return pass < settlePasses ? PassSamples{directSamples, residualSamples, cameraSamples}
                               : PassSamples{directSamplesLate, residualSamplesLate,
                                             cameraSamplesLate};
  }
  // Per-pixel work of pass k in path units (G-buffer and light samples about half a path,
  // an extra camera ray a tenth).
  double gbufferCost(uint32_t pass) const { return 0.25 + 0.1 * (samplesOfPass(pass).camera - 1.0); }
  double pixelCost(uint32_t pass) const {
    PassSamples s = samplesOfPass(pass);
    return gbufferCost(pass) + 0.25 + 0.5 * s.direct + s.residual;
  }
};

}  // namespace osr::oneshot
