// The maps file `osr-vk unet --in` reads: raw little-endian fp32 maps, N x 7 x 32 x 32 (the
// network's input, channels as docs/maps_format.md's input.npy without the .npy header).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace osr::app {

struct MapsFile {
  std::vector<char> bytes;  // N whole maps
  uint32_t maps = 0;        // N >= 1
};

// Reads `path`; InputError "<path>: problem" unless it is a regular file holding a positive
// whole number of maps.
MapsFile readMapsFile(const std::string& path);

}  // namespace osr::app
