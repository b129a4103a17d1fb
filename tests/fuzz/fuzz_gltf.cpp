// Fuzz target: scene::loadScene, the glTF/GLB loader with its external buffers and images.
// An input is the scene file, optionally followed by files it references, each as
// "\0osr-fuzz-file NAME\n" and its bytes (NAME: letters, digits, '.', '_', '-'), so that the
// fuzzer mutates .bin buffers and PNG/JPEG textures as well as the JSON and GLB chunks. The
// scene is written as scene.gltf (the loader tells GLB from glTF by content) beside its files.
#include <exception>
#include <string>
#include <string_view>

#include "common/error.h"
#include "fuzz/fuzz_support.h"
#include "scene/scene.h"

namespace {

constexpr std::string_view kMarker("\0osr-fuzz-file ", 15);

bool validName(std::string_view name) {
  if (name.empty() || name.size() > 64 || name == "." || name == ".." || name == "scene.gltf")
    return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-'))
      return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  osr::fuzz::clearScratch();
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  size_t at = all.find(kMarker);
  const std::string_view scene = all.substr(0, at);
  while (at != std::string_view::npos) {
    const size_t nameStart = at + kMarker.size();
    const size_t newline = all.find('\n', nameStart);
    if (newline == std::string_view::npos) break;
    const size_t next = all.find(kMarker, newline + 1);
    const std::string_view name = all.substr(nameStart, newline - nameStart);
    const std::string_view bytes = all.substr(newline + 1, next == std::string_view::npos
                                                               ? std::string_view::npos
                                                               : next - newline - 1);
    if (validName(name))
      osr::fuzz::writeScratch(std::string(name), reinterpret_cast<const uint8_t*>(bytes.data()),
                              bytes.size());
    at = next;
  }
  const std::string path = osr::fuzz::writeScratch(
      "scene.gltf", reinterpret_cast<const uint8_t*>(scene.data()), scene.size());
  try {
    const osr::scene::Scene s = osr::scene::loadScene(path);
    // What every command does next with a loaded scene, on the host.
    osr::scene::selectCamera(s, "", 1.0f);
  } catch (const osr::InputError& e) {
    osr::fuzz::checkMessage(e, path);
  }
  return 0;
}
