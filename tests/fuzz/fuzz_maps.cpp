// Fuzz target: app::readMapsFile, the fp32 maps file `osr-vk unet --in` reads.
#include <string>

#include "app/maps_file.h"
#include "common/error.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = osr::fuzz::writeScratch("maps.f32", data, size);
  try {
    const osr::app::MapsFile f = osr::app::readMapsFile(path);
    if (f.maps == 0 || f.bytes.size() != size) std::abort();  // a whole file of whole maps
  } catch (const osr::InputError& e) {
    osr::fuzz::checkMessage(e, path);
  }
  return 0;
}
