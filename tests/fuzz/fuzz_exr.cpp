// Fuzz target: image::readExrRgb, the OpenEXR reader of `osr-vk compare` and the benchmarks.
// An input is the file; its default RGB (or Y) layer is read, then the layer `noisy`.
#include <string>

#include "common/error.h"
#include "fuzz/fuzz_support.h"
#include "image/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = osr::fuzz::writeScratch("image.exr", data, size);
  for (const char* layer : {"", "noisy"}) {
    try {
      osr::image::readExrRgb(path, layer);
    } catch (const osr::InputError& e) {
      osr::fuzz::checkMessage(e, path);
    }
  }
  return 0;
}
