// The options of `osr-vk maps` (docs/maps_format.md) read from the command line and checked
// before the scene is read: what cmd_maps.cpp runs on, and what tests/fuzz/fuzz_cli.cpp feeds
// arbitrary argument lists.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/scene_setup.h"
#include "vk/context.h"

namespace osr::app {

struct MapsOptions {
  std::string scenePath, outDir;
  std::optional<long long> grid;      // --grid R
  std::optional<std::string> pixelText;  // --pixels as given
  std::vector<glm::uvec2> pixels;     // --pixels parsed
  uint32_t referenceSpp = 0, views = 1, seed = 0;
  SceneOptions scene;
  vk::ContextOptions device;
  bool quiet = false;
};

// InputError naming the option on anything malformed, missing or contradictory.
MapsOptions parseMapsOptions(const std::vector<std::string>& args);

// "x,y;x,y;...": at least one pair of non-negative integers below 10^9.
std::vector<glm::uvec2> parsePixels(const std::string& text);

}  // namespace osr::app
