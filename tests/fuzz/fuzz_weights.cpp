// Fuzz target: packed U-Net weights (.osrw, nn_kernels/weights_format.h), parsed as a map
// denoiser and as an image denoiser. Each input is parsed as given and again with its CRC-32
// field set to the checksum of its bytes, so that mutations reach the JSON header and the
// tensor table behind the checksum check.
#include <cstring>
#include <span>
#include <vector>

#include "common/error.h"
#include "fuzz/fuzz_support.h"
#include "nn_kernels/weights.h"
#include "nn_kernels/weights_format.h"

namespace {

void parseBoth(std::span<const uint8_t> bytes) {
  const std::string name = "fuzz.osrw";
  try {
    osr::nn::UNetWeights w = osr::nn::UNetWeights::parse(bytes, name);
    w.flopsPerMap();
    w.requireConventions(osr::nn::kMappingConcentric, osr::nn::kNormalizationLogMean10);
  } catch (const osr::InputError& e) {
    osr::fuzz::checkMessage(e, name);
  }
  try {
    osr::nn::ImageUNetWeights::parse(bytes, name).flopsPerPixel();
  } catch (const osr::InputError& e) {
    osr::fuzz::checkMessage(e, name);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  parseBoth({data, size});
  if (size >= osr::nn::kPrefixBytes) {
    std::vector<uint8_t> fixed(data, data + size);
    const uint32_t crc = osr::nn::crc32(fixed.data() + osr::nn::kPrefixBytes,
                                        fixed.size() - osr::nn::kPrefixBytes);
    std::memcpy(fixed.data() + osr::nn::kOffsetChecksum, &crc, 4);
    parseBoth(fixed);
  }
  return 0;
}
