// What the OSR integrator is asked to do (src/osr/osr_integrator.h); the CLI fills it from
// --denoiser, --weights, --grid-start, --grid-min and friends.
#pragma once
#include <cstdint>
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

struct OsrSettings {
  Denoiser denoiser = Denoiser::Blur;
  std::string weightsPath;       // packed U-Net (tools/weights_pack.py); needed for Unet
  uint32_t gridStart = 16;       // grid spacing r of the first pass, pixels
  uint32_t gridMin = 16;         // finest spacing the schedule refines to
  double mapShare = 0.25;        // largest share of the work map passes may take
  uint32_t pathsPerTexel = 1;    // paths per map texel (1: the one-shot maps of DESIGN.md)
  uint32_t directSamples = 16;   // light samples per pixel per pass
  uint32_t residualSamples = 1;  // residual paths per pixel per pass (0: maps only, biased)
  uint32_t glossySamples = 4;    // map lookups per pixel for wide glossy lobes
  double residualRamp = 64.0;    // n0: the residual is blended in by n / (n + n0)
  uint32_t maxChunkMaps = 512;   // maps traced and denoised per chunk (memory bound)
  bool keepAllMaps = false;      // one chunk for all maps of a pass (for --dump-maps)
};

}  // namespace osr::oneshot
