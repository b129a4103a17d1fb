// Fuzz target: the osr-vk command line up to the point where a file is read or a device made:
// the render command's options and their cross-checks (app/render_options.h), or with a first
// argument "maps" the maps command's (app/maps_options.h). An input is the argument list,
// arguments separated by NUL bytes (at most 64 of them).
#include <string>
#include <vector>

#include "app/args.h"
#include "app/maps_options.h"
#include "app/render_options.h"
#include "common/error.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> args(1);
  for (size_t i = 0; i < size; ++i) {
    if (data[i] != 0) {
      args.back() += char(data[i]);
    } else {
      if (args.size() == 64) break;
      args.emplace_back();
    }
  }
  try {
    if (osr::app::helpRequested(args)) return 0;  // main prints the usage
    if (args[0] == "maps") {
      osr::app::parseMapsOptions({args.begin() + 1, args.end()});
    } else {
      const osr::app::RenderOptions o = osr::app::parseRenderOptions(args);
      osr::app::checkRenderOptions(o);
    }
  } catch (const osr::InputError& e) {
    osr::fuzz::checkMessage(e, "");
  }
  return 0;
}
