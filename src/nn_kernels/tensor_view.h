// A channel slice of an NCHW tensor in a device buffer, as the U-Net passes bind it.
#pragma once
#include <cstdint>

#include "vk/buffer.h"

namespace osr::nn {

struct TensorView {
  vk::BufferRange range;  // element 0 of map 0, channel 0 of the whole buffer tensor
  uint32_t cTotal = 0;    // channels per map in the buffer
  uint32_t c0 = 0;        // first channel of the slice
  bool half = false;      // packed fp16 (two per 32-bit word) instead of fp32
};

// Splits `groups` workgroups over (x, y) so neither exceeds the per-dimension limit.
inline void splitGroups(uint64_t groups, uint32_t& x, uint32_t& y) {
  x = uint32_t(groups < 65535 ? (groups ? groups : 1) : 65535);
  y = uint32_t((groups + x - 1) / x);
}

}  // namespace osr::nn
