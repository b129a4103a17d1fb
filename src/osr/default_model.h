// The model shipped in models/ (docs/training.md), built into the executable so that osr-vk
// denoises with it from any folder; empty in a build made without one.
#pragma once
#include <cstdint>
#include <span>

namespace osr::oneshot {

// The packed weights file's bytes (tools/weights_pack.py format), or an empty span.
std::span<const uint8_t> defaultModelBytes();
// How messages name it.
inline constexpr char kDefaultModelName[] = "built-in model models/osr_unet.osrw";

}  // namespace osr::oneshot
