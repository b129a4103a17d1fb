// The benchmarks of osr-bench; each prints JSON lines (see bench/json.h) and returns an exit code.
#pragma once
#include <string>
#include <vector>

namespace osr::bench {
int runFill(const std::vector<std::string>& args);  // memory bandwidth of util_fill
int runPathtrace(const std::vector<std::string>& args);  // path tracer spp/s, Mpaths/s
}  // namespace osr::bench
