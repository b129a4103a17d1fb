// Fuzz target: scene::loadEnvironment, equirectangular environment maps (.exr through OpenEXR,
// .hdr through stb_image), then the importance-sampling tables every loaded map gets
// (environmentCdf). An input that starts with OpenEXR's magic number is written as env.exr,
// any other as env.hdr.
#include <cstring>
#include <string>

#include "common/error.h"
#include "fuzz/fuzz_support.h"
#include "scene/environment.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const uint8_t kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  const bool exr = size >= 4 && std::memcmp(data, kExrMagic, 4) == 0;
  const std::string path = osr::fuzz::writeScratch(exr ? "env.exr" : "env.hdr", data, size);
  try {
    const osr::scene::Environment env = osr::scene::loadEnvironment(path);
    osr::scene::environmentCdf(env);
  } catch (const osr::InputError& e) {
    osr::fuzz::checkMessage(e, path);
  }
  return 0;
}
