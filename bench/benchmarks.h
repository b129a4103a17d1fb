// The benchmarks of osr-bench; each prints JSON lines (see bench/json.h) and returns an exit code.
#pragma once
#include <string>
#include <vector>

namespace osr::bench {
int runFill(const std::vector<std::string>& args);  // memory bandwidth of util_fill
int runPathtrace(const std::vector<std::string>& args);  // path tracer spp/s, Mpaths/s
int runBvh(const std::vector<std::string>& args);   // GPU BVH build vs CPU SAH and Embree
int runTrace(const std::vector<std::string>& args); // rays/s of bvh_trace_rays vs Embree
int runUnet(const std::vector<std::string>& args);  // U-Net maps/s vs PyTorch
}  // namespace osr::bench
