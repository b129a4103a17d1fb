// `osr-bench --record`: each JSON line a benchmark prints is also appended to
// bench/results/<benchmark>.jsonl in the source tree, with the date, the commit and the machine,
// so the results are data anyone can regenerate and compare (docs/benchmarks.md).
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <string>
#include <stdexcept>
#include <thread>

#include "bench/json.h"
#include "common/error.h"

#ifndef OSR_SOURCE_DIR
#error "OSR_SOURCE_DIR: the build defines it (CMakeLists.txt), --record appends under it"
#endif

namespace osr::bench {
namespace {
int gFile = -1;        // the open results file, or -1 when not recording
std::string gContext;  // "date", "commit", "machine" fields, without braces

// One line of a command's output (empty when it fails), e.g. git's short hash.
std::string commandLine(const std::string& command) {
  std::string out;
  if (FILE* p = popen(command.c_str(), "r")) {
    char buf[256];
    if (std::fgets(buf, sizeof buf, p)) out = buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) q += c;
  }
  return q + "\"";
}

// Host name, CPU model and logical core count: what a CPU device's timings depend on.
std::string machine() {
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  std::string model = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return std::string(host) + ": " + model + ", " + std::to_string(std::thread::hardware_concurrency()) +
         " cores";
}
}  // namespace

void startRecording(const std::string& benchmark) {
  if (gFile >= 0) close(gFile);
  const std::string path = std::string(OSR_SOURCE_DIR) + "/bench/results/" + benchmark + ".jsonl";
  gFile = open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (gFile < 0) throw InputError("--record: " + path + ": " + std::strerror(errno));
  const std::string git = "git -C '" + std::string(OSR_SOURCE_DIR) + "' ";
  std::string commit = commandLine(git + "rev-parse --short HEAD 2>/dev/null");
  if (commit.empty()) commit = "unknown";
  // Changes to tracked files other than the results make the figures not the commit's.
  else if (!commandLine(git + "status --porcelain --untracked-files=no -- . ':!bench/results' 2>/dev/null")
                .empty())
    commit += "-dirty";
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc);
  gContext = "\"date\": " + quoted(date) + ", \"commit\": " + quoted(commit) + ", \"machine\": " +
             quoted(machine());
}

void recordLine(const std::string& body) {
  if (gFile < 0) return;
  const std::string line = "{" + gContext + ", " + body + "}\n";
  // One write() on an O_APPEND descriptor: a line is never interleaved with another writer's.
  if (write(gFile, line.data(), line.size()) != static_cast<ssize_t>(line.size()))
    throw std::runtime_error(std::string("--record: appending a line failed: ") + std::strerror(errno));
}
}  // namespace osr::bench
