// The benchmarks of osr-bench; each prints JSON lines (see bench/json.h) and returns an exit
// code. Each usage is printed by `osr-bench NAME --help`.
#pragma once
#include <string>
#include <vector>

namespace osr::bench {
inline constexpr char kFillUsage[] = "osr-bench fill";
int runFill(const std::vector<std::string>& args);  // memory bandwidth of util_fill
inline constexpr char kPathtraceUsage[] = "osr-bench pathtrace [--scene cornell|room] [--size N] [--spp N]";
int runPathtrace(const std::vector<std::string>& args);  // path tracer spp/s, Mpaths/s
inline constexpr char kBvhUsage[] =
    "osr-bench bvh [--scene NAME] [--repeat N] [--treelet-rounds N] [--treelet-leaves N]\n"
    "              [--treelet-min-triangles N]";
int runBvh(const std::vector<std::string>& args);   // GPU BVH build vs CPU SAH and Embree
inline constexpr char kTraceUsage[] =
    "osr-bench trace [--scene NAME] [--side N] [--repeat N] [--bvh-access auto|storage|texel]";
int runTrace(const std::vector<std::string>& args); // rays/s of bvh_trace_rays vs Embree
inline constexpr char kUnetUsage[] =
    "osr-bench unet [--k 16,64] [--batch 64,256,1024,4096] [--precision fp32,fp16]\n"
    "               [--no-pytorch] [--min-seconds S] [--tile HxW] [--chunk N] [--share N]\n"
    "               [--profile]";
int runUnet(const std::vector<std::string>& args);  // U-Net maps/s vs PyTorch
inline constexpr char kOsrUsage[] =
    "osr-bench osr [--scene cornell|room] [--size N] [--budgets 2,5,10,30,60]\n"
    "              [--denoiser blur|none|unet] [--weights FILE] [--modes osr,path]";
int runOsr(const std::vector<std::string>& args);   // OSR vs path tracing at equal time
}  // namespace osr::bench
