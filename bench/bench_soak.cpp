// soak: the live viewer driven for many minutes as a person would use it (camera moves, mode
// and layer changes, resizes, saves, screenshots) under Xvfb with the validation layer on. It
// samples osr-vk's resident memory, counts validation messages and checks every saved file,
// then prints one line: memory growth after the first minute (< 5 %), no validation message,
// every saved file a whole image, exit 0. A benchmark, not a test: it runs 20 minutes.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/args.h"
#include "bench/benchmarks.h"
#include "bench/json.h"
#include "common/error.h"
#include "image/image_io.h"
#include "vk/context.h"

namespace osr::bench {

namespace fs = std::filesystem;

namespace {

// One cycle of the script, `kCycleS` seconds, commands at offsets from the cycle's start. It
// ends in the state it began in (OSR at 512 x 512 after a restart is not that state; the
// preview at 300 x 300 is, and the memory sample is taken there).
constexpr double kCycleS = 60.0;
struct Step {
  double at;
  const char* command;
};
constexpr Step kCycle[] = {
    {0.0, "mode osr"},       {0.5, "resize 832 512"}, {1.0, "reset"},
    {8.0, "orbit 25 5"},     {14.0, "key s"},         {16.0, "pan 0.2 0.1"},
    {20.0, "zoom 1.3"},      {24.0, "mode path"},     {30.0, "key s"},
    {32.0, "key 3"},         {33.0, "key 1"},         {34.0, "resize 620 300"},
    {40.0, "mode preview"},  {42.0, "fly 0.1 0 0"},   {46.0, "key s"},
    {48.0, "screenshot"},    {52.0, "key plus"},      {53.0, "key minus"},
    {56.0, "orbit -25 -5"},   {59.0, "stats"},
};
// Each cycle's `stats` line on stdout marks its memory sample (preview at 300 x 300, after the
// last move): the same state every cycle, whatever the time the window took to open.

std::string writeScript(const fs::path& dir, int cycles) {
  const fs::path path = dir / "soak.txt";
  std::ofstream out(path);
  out << "# osr-bench soak: " << cycles << " cycles of " << kCycleS << " s\n";
  for (int c = 0; c < cycles; ++c)
    for (const Step& s : kCycle) {
      out << "at " << c * kCycleS + s.at << "\n" << s.command;
      if (std::string(s.command) == "screenshot")
        out << " " << (dir / ("shot-" + std::to_string(c) + ".png")).string();
      out << "\n";
    }
  out << "at " << cycles * kCycleS << "\nstats\nquit\n";
  return path.string();
}

// Resident memory of `pid` in KiB (VmRSS), 0 once it has exited.
long residentKiB(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

size_t countOf(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string sceneFile(const std::string& name) {
  if (name == "cornell" || name == "room")
    return std::string(OSR_SOURCE_DIR) + "/scenes/" + name + "/" + name + ".gltf";
  if (!fs::exists(name)) throw InputError("--scene: " + name + ": no such file");
  return name;
}

}  // namespace

int runSoak(const std::vector<std::string>& args) {
  app::Args a(args, "soak");
  const double minutes = a.number("--minutes", 1, 600).value_or(20);
  const std::string scene = sceneFile(a.value("--scene").value_or("room"));
  a.finish();
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0)
    throw InputError("soak: needs xvfb-run (apt-get install xvfb)");
  const std::string device = vk::Context().caps().deviceName;
  const int cycles = std::max(1, int(minutes * 60.0 / kCycleS + 0.5));
  char tmpl[] = "/tmp/osr_soak_XXXXXX";
  if (!mkdtemp(tmpl)) throw DeviceError("soak: cannot make a temporary folder");
  const fs::path dir = tmpl, saves = dir / "saves";
  fs::create_directories(saves);
  const std::string script = writeScript(dir, cycles);
  const std::string osrVk = (fs::read_symlink("/proc/self/exe").parent_path() / "osr-vk").string();
  const fs::path pidFile = dir / "pid", errFile = dir / "stderr.txt", outFile = dir / "stdout.txt";

  // sh writes its pid and execs osr-vk in its place, so the pid is osr-vk's.
  const std::string command =
      "xvfb-run -a -s '-screen 0 1600x1200x24' sh -c 'echo $$ > \"" + pidFile.string() +
      "\"; exec \"" + osrVk + "\" --validation --width 512 --height 512 --save-dir \"" +
      saves.string() + "\" --viewer-script \"" + script + "\" \"" + scene + "\"' >\"" +
      outFile.string() + "\" 2>\"" + errFile.string() + "\"";
  const pid_t runner = fork();
  if (runner < 0) throw DeviceError("soak: fork failed");
  if (runner == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const auto t0 = std::chrono::steady_clock::now();
  auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  pid_t viewer = 0;
  std::vector<long> samples, perCycle;  // KiB: every half second; at each cycle's stats line
  int status = 0;
  for (;;) {
    if (waitpid(runner, &status, WNOHANG) == runner) break;
    if (!viewer) std::ifstream(pidFile) >> viewer;
    if (viewer) {
      const long kib = residentKiB(viewer);
      if (kib > 0) samples.push_back(kib);
      const size_t statsLines = countOf(slurp(outFile), "{");
      if (kib > 0 && statsLines > perCycle.size() && perCycle.size() < size_t(cycles))
        perCycle.push_back(kib);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    // A hung viewer: the script's length plus ten minutes.
    if (seconds() > cycles * kCycleS + 600.0) {
      kill(viewer ? viewer : runner, SIGKILL);
      waitpid(runner, &status, 0);
      break;
    }
  }
  const int exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  const double wallS = seconds();

  long peak = 0;
  for (long s : samples) peak = std::max(peak, s);
  const double first = perCycle.empty() ? 0.0 : double(perCycle.front());
  const double last = perCycle.empty() ? 0.0 : double(perCycle.back());
  const double growthPct = first > 0.0 ? 100.0 * (last - first) / first : 0.0;
  // Each cycle's sample, so that a trend (a leak) shows apart from a step (a cache filled once).
  std::vector<long long> cycleMib;
  for (long kib : perCycle) cycleMib.push_back((kib + 512) / 1024);

  const std::string err = slurp(errFile);
  const size_t validation = countOf(err, "osr-vk: validation");
  size_t files = 0, valid = 0;
  for (const auto& e : fs::directory_iterator(saves)) {
    ++files;
    valid += image::isCompleteImage(e.path().string());
  }
  for (int c = 0; c < cycles; ++c) {
    const fs::path shot = dir / ("shot-" + std::to_string(c) + ".png");
    if (!fs::exists(shot)) continue;
    ++files;
    valid += image::isCompleteImage(shot.string());
  }
  const size_t expected = size_t(cycles) * (3 * 2 + 1);  // three saves of two files, a screenshot
  const bool pass = exitCode == 0 && validation == 0 && files == expected && valid == files &&
                    perCycle.size() == size_t(cycles) && growthPct < 5.0;
  JsonLine()
      .str("bench", "soak")
      .str("device", device)
      .str("scene", fs::path(scene).filename().string())
      .num("minutes", minutes)
      .num("wall_s", wallS)
      .integer("cycles", cycles)
      .integer("exit_code", exitCode)
      .integer("validation_messages", static_cast<long long>(validation))
      .integer("files_saved", static_cast<long long>(files))
      .integer("files_expected", static_cast<long long>(expected))
      .integer("files_valid", static_cast<long long>(valid))
      .num("rss_after_1min_mib", first / 1024.0)
      .num("rss_end_mib", last / 1024.0)
      .num("rss_peak_mib", peak / 1024.0)
      .num("rss_growth_after_1min_pct", growthPct)
      .integer("rss_samples", static_cast<long long>(samples.size()))
      .integer("rss_cycle_samples", static_cast<long long>(perCycle.size()))
      .integers("rss_per_cycle_mib", cycleMib)
      .str("result", pass ? "pass" : "fail")
      .print();
  if (!pass) {
    std::fprintf(stderr, "osr-bench: soak: failed; the run's files are in %s\n", dir.c_str());
    if (exitCode != 0) std::fprintf(stderr, "%s", err.substr(err.size() > 2000 ? err.size() - 2000 : 0).c_str());
    return kExitInternal;
  }
  fs::remove_all(dir);
  return kExitOk;
}

}  // namespace osr::bench
