// The image denoiser shipped in models/ (docs/denoise.md), built into the executable as the
// osr/default_model.h map model is; empty in a build made without models/osr_image_denoiser.osrw.
#pragma once
#include <cstdint>
#include <span>

namespace osr::render {

std::span<const uint8_t> defaultImageModelBytes();

}  // namespace osr::render
