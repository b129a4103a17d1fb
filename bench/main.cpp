// osr-bench: benchmarks, one JSON object per line on stdout. `osr-bench NAME [options]` runs
// one; with no name, all. Each benchmark verifies its output before timing it. `--help` or
// `-h` anywhere prints the usage (of NAME, when given) on stdout and exits 0.
//
// Exit code (DESIGN.md): 0 success, 2 bad input, 1 failure (device, verification, internal).
// Running all, each benchmark runs even if an earlier one failed, and the run exits with the
// worst code, bad input first: it is the one the user can fix, and it usually means the other
// failures are its consequence.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "app/args.h"
#include "bench/benchmarks.h"
#include "common/error.h"

namespace {
struct Benchmark {
  const char* name;
  const char* usage;
  int (*run)(const std::vector<std::string>&);
};
const Benchmark kBenchmarks[] = {
    {"fill", osr::bench::kFillUsage, osr::bench::runFill},
    {"pathtrace", osr::bench::kPathtraceUsage, osr::bench::runPathtrace},
    {"bvh", osr::bench::kBvhUsage, osr::bench::runBvh},
    {"trace", osr::bench::kTraceUsage, osr::bench::runTrace},
    {"unet", osr::bench::kUnetUsage, osr::bench::runUnet},
    {"osr", osr::bench::kOsrUsage, osr::bench::runOsr},
};

// The worse of two exit codes: bad input, then any other failure, then success.
int worst(int a, int b) {
  if (a == osr::kExitBadInput || b == osr::kExitBadInput) return osr::kExitBadInput;
  return a || b ? osr::kExitInternal : osr::kExitOk;
}

// Runs one benchmark; an exception is one stderr line and its exit code.
int runOne(const Benchmark& b, const std::vector<std::string>& args) {
  try {
    return b.run(args);
  } catch (const osr::InputError& e) {
    std::fprintf(stderr, "osr-bench: %s\n", e.what());
    return osr::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "osr-bench: error: %s\n", e.what());
    return osr::kExitInternal;
  } catch (...) {
    std::fprintf(stderr, "osr-bench: error: unknown exception in %s\n", b.name);
    return osr::kExitInternal;
  }
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  const Benchmark* chosen = nullptr;
  for (const Benchmark& b : kBenchmarks)
    if (!args.empty() && args[0] == b.name) chosen = &b;
  if (osr::app::helpRequested(args)) {
    if (chosen) {
      std::printf("usage: %s\n", chosen->usage);
    } else {
      std::printf("usage: osr-bench [NAME [options]]   no NAME: every benchmark, default options\n");
      for (const Benchmark& b : kBenchmarks) {
        std::string indented = "  " + std::string(b.usage);
        for (size_t i = 0; (i = indented.find('\n', i)) != std::string::npos; i += 3)
          indented.insert(i + 1, "  ");
        std::printf("%s\n", indented.c_str());
      }
    }
    return osr::kExitOk;
  }
  if (chosen) return runOne(*chosen, {args.begin() + 1, args.end()});
  if (!args.empty()) {
    std::fprintf(stderr, "osr-bench: unknown benchmark '%s' (see osr-bench --help)\n", args[0].c_str());
    return osr::kExitBadInput;
  }
  int rc = osr::kExitOk;
  for (const Benchmark& b : kBenchmarks) rc = worst(rc, runOne(b, {}));
  return rc;
}
