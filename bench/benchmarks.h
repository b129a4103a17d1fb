// The benchmarks of osr-bench; each prints JSON lines (see bench/json.h) and returns an exit code.
#pragma once
#include <string>
#include <vector>

namespace osr::bench {
int runFill(const std::vector<std::string>& args);  // memory bandwidth of util_fill
int runUnet(const std::vector<std::string>& args);  // U-Net maps/s vs PyTorch
}  // namespace osr::bench
