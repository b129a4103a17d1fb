// osr-bench: benchmarks, one JSON object per line on stdout. `osr-bench NAME [options]` runs
// one; `osr-bench all` runs every one with default options; with no name it lists them, one
// line each (running them all takes many minutes: not what a person trying the command wants).
// Each benchmark verifies its output before timing it. `--help` or `-h` anywhere prints the
// usage (of NAME, when given) on stdout and exits 0. `--record` anywhere also appends every
// line to bench/results/NAME.jsonl in the source tree, with date, commit and machine.
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
#include "bench/json.h"
#include "common/error.h"

namespace {
struct Benchmark {
  const char* name;
  const char* summary;
  const char* usage;
  int (*run)(const std::vector<std::string>&);
  bool inAll = true;  // run by `osr-bench all` (not the soak, animation or osr-error: long)
};
const Benchmark kBenchmarks[] = {
    {"fill", osr::bench::kFillSummary, osr::bench::kFillUsage, osr::bench::runFill},
    {"pathtrace", osr::bench::kPathtraceSummary, osr::bench::kPathtraceUsage, osr::bench::runPathtrace},
    {"bvh", osr::bench::kBvhSummary, osr::bench::kBvhUsage, osr::bench::runBvh},
    {"trace", osr::bench::kTraceSummary, osr::bench::kTraceUsage, osr::bench::runTrace},
    {"unet", osr::bench::kUnetSummary, osr::bench::kUnetUsage, osr::bench::runUnet},
    {"osr", osr::bench::kOsrSummary, osr::bench::kOsrUsage, osr::bench::runOsr},
    {"denoise", osr::bench::kDenoiseSummary, osr::bench::kDenoiseUsage, osr::bench::runDenoise},
    {"osr-error", osr::bench::kOsrErrorSummary, osr::bench::kOsrErrorUsage,
     osr::bench::runOsrError, false},
    {"animation", osr::bench::kAnimationSummary, osr::bench::kAnimationUsage,
     osr::bench::runAnimation, false},
    {"soak", osr::bench::kSoakSummary, osr::bench::kSoakUsage, osr::bench::runSoak, false},
};

// The worse of two exit codes: bad input, then any other failure, then success.
int worst(int a, int b) {
  if (a == osr::kExitBadInput || b == osr::kExitBadInput) return osr::kExitBadInput;
  return a || b ? osr::kExitInternal : osr::kExitOk;
}

// Runs one benchmark; an exception is one stderr line and its exit code.
int runOne(const Benchmark& b, const std::vector<std::string>& args, bool record) {
  try {
    if (record) osr::bench::startRecording(b.name);
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

void printList(FILE* out) {
  std::fprintf(out,
               "usage: osr-bench NAME [options]   one benchmark (osr-bench NAME --help: its options)\n"
               "       osr-bench all              every benchmark but soak, animation, osr-error\n"
               "  --record  also append each line to bench/results/NAME.jsonl in the source tree\n"
               "benchmarks:\n");
  for (const Benchmark& b : kBenchmarks) std::fprintf(out, "  %-10s %s\n", b.name, b.summary);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args;
  bool record = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--record") != 0) {
      args.push_back(argv[i]);
    } else if (record) {
      std::fprintf(stderr, "osr-bench: --record: given twice\n");
      return osr::kExitBadInput;
    } else {
      record = true;
    }
  }
  const Benchmark* chosen = nullptr;
  for (const Benchmark& b : kBenchmarks)
    if (!args.empty() && args[0] == b.name) chosen = &b;
  if (osr::app::helpRequested(args)) {
    if (chosen)
      std::printf("usage: %s\n", chosen->usage);
    else
      printList(stdout);
    return osr::kExitOk;
  }
  if (args.empty()) {
    if (record) {
      std::fprintf(stderr, "osr-bench: --record: name a benchmark (osr-bench lists them)\n");
      return osr::kExitBadInput;
    }
    printList(stdout);
    return osr::kExitOk;
  }
  if (chosen) return runOne(*chosen, {args.begin() + 1, args.end()}, record);
  if (args[0] == "all") {
    if (args.size() > 1) {
      std::fprintf(stderr, "osr-bench: all: takes no options (run one benchmark to set them)\n");
      return osr::kExitBadInput;
    }
    int rc = osr::kExitOk;
    for (const Benchmark& b : kBenchmarks)
      if (b.inAll) rc = worst(rc, runOne(b, {}, record));
    return rc;
  }
  std::fprintf(stderr, "osr-bench: unknown benchmark '%s' (osr-bench lists them)\n", args[0].c_str());
  return osr::kExitBadInput;
}
