// osr-bench: benchmarks, one JSON object per line on stdout. `osr-bench NAME [options]` runs
// one; with no name, all. Each benchmark verifies its output before timing it.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "bench/benchmarks.h"
#include "common/error.h"

namespace {
struct Benchmark {
  const char* name;
  int (*run)(const std::vector<std::string>&);
};
const Benchmark kBenchmarks[] = {
    {"fill", osr::bench::runFill},
    {"pathtrace", osr::bench::runPathtrace},
    {"bvh", osr::bench::runBvh},
    {"trace", osr::bench::runTrace},
    {"unet", osr::bench::runUnet},
};
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
      std::printf("usage: osr-bench [NAME] [options]\nbenchmarks:");
      for (const Benchmark& b : kBenchmarks) std::printf(" %s", b.name);
      std::printf("\n");
      return 0;
    }
    if (args.empty()) {
      int rc = 0;
      for (const Benchmark& b : kBenchmarks) rc |= b.run({});
      return rc;
    }
    for (const Benchmark& b : kBenchmarks)
      if (args[0] == b.name) return b.run({args.begin() + 1, args.end()});
    std::fprintf(stderr, "osr-bench: unknown benchmark '%s'\n", args[0].c_str());
    return osr::kExitBadInput;
  } catch (const osr::InputError& e) {
    std::fprintf(stderr, "osr-bench: %s\n", e.what());
    return osr::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "osr-bench: error: %s\n", e.what());
    return osr::kExitInternal;
  }
}
