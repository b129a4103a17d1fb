#include "app/maps_options.h"

#include <filesystem>
#include <sstream>

#include "app/args.h"
#include "app/device_options.h"
#include "common/error.h"
#include "common/input_file.h"

namespace osr::app {

std::vector<glm::uvec2> parsePixels(const std::string& text) {
  std::vector<glm::uvec2> pixels;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ';')) {
    const size_t comma = item.find(',');
    const bool digitsOnly = item.find_first_not_of("0123456789,") == std::string::npos;
    if (!digitsOnly || comma == std::string::npos || comma == 0 || comma + 1 == item.size() ||
        item.find(',', comma + 1) != std::string::npos || comma > 9 || item.size() - comma > 10)
      throw InputError("--pixels: '" + item + "' is not x,y (expected x,y;x,y;...)");
    pixels.emplace_back(std::stoul(item.substr(0, comma)), std::stoul(item.substr(comma + 1)));
  }
  if (pixels.empty()) throw InputError("--pixels: no pixels given (expected x,y;x,y;...)");
  return pixels;
}

MapsOptions parseMapsOptions(const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  Args a(args, "maps");
  MapsOptions o;
  auto outDir = a.value("--out");
  o.grid = a.integer("--grid", 1, 16384);
  o.pixelText = a.value("--pixels");
  o.referenceSpp = uint32_t(a.integer("--reference-spp", 0, 1 << 20).value_or(0));
  o.views = uint32_t(a.integer("--views", 1, 1 << 20).value_or(1));
  o.seed = uint32_t(a.integer("--seed", 0, 0xffffffffll).value_or(0));
  o.scene = readSceneOptions(a);
  o.device = readDeviceOptions(a);
  o.quiet = a.flag("--quiet");
  auto files = a.positional();
  a.finish();
  if (files.size() != 1) throw InputError("maps: expected exactly one scene file");
  if (!outDir) throw InputError("maps: give --out DIR");
  if (o.grid && o.pixelText) throw InputError("maps: give --grid R or --pixels x,y;..., not both");
  if (!o.grid && !o.pixelText) throw InputError("maps: give --grid R or --pixels x,y;x,y;...");
  if (auto problem = folderProblem(*outDir)) throw InputError("--out: " + *outDir + *problem);
  if (o.pixelText) o.pixels = parsePixels(*o.pixelText);
  o.scenePath = files[0];
  o.outDir = *outDir;
  return o;
}

}  // namespace osr::app
