// Fuzz target: viewer::parseViewerScript, the --viewer-script language (viewer_script.h).
// A script it accepts must hold what Viewer::runScript converts without checks: numbers that
// stay finite (and a zoom positive) as floats, and counts (camera, wait-units) that fit 32 bits.
#include <cmath>
#include <cstdlib>
#include <string>

#include "common/error.h"
#include "fuzz/fuzz_support.h"
#include "viewer/viewer_script.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string name = "script.txt";
  try {
    const auto script =
        osr::viewer::parseViewerScript(std::string(reinterpret_cast<const char*>(data), size), name);
    for (const osr::viewer::ScriptCommand& c : script)
      for (double x : c.numbers) {
        const bool floats = c.name == "orbit" || c.name == "pan" || c.name == "zoom" || c.name == "fly";
        if (floats && !(std::isfinite(float(x)) && (c.name != "zoom" || float(x) > 0.0f)))
          std::abort();
        if ((c.name == "camera" || c.name == "wait-units") && !(x >= 0.0 && x <= 4294967295.0))
          std::abort();
      }
  } catch (const osr::InputError& e) {
    osr::fuzz::checkMessage(e, name);
  }
  return 0;
}
