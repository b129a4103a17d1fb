// Test helpers: runs the built osr-vk (OSR_BINARY_DIR from the environment, else the build's)
// through the shell and captures its exit code and its stdout + stderr; reads its notes.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

namespace osr::test {

struct CliResult {
  int code;
  std::string out;
};

inline CliResult runOsrVk(const std::string& args) {
  const char* env = std::getenv("OSR_BINARY_DIR");
  std::string cmd = std::string(env ? env : OSR_BINARY_DIR) + "/osr-vk " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 512> buf;
  while (fgets(buf.data(), buf.size(), p)) out += buf.data();
  int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}

// osr-vk's note on a --time render, in seconds on its own clock: "the render loop ran from FROM
// to TO s, holding back HELD s ...", read from its output; nothing when the output has none.
struct RenderLoopNote {
  double from, to, held;
};

inline std::optional<RenderLoopNote> renderLoopNote(const std::string& out) {
  const size_t at = out.find("the render loop ran from ");
  RenderLoopNote n{};
  if (at == std::string::npos ||
      std::sscanf(out.c_str() + at, "the render loop ran from %lf to %lf s, holding back %lf", &n.from,
                  &n.to, &n.held) != 3)
    return std::nullopt;
  return n;
}

}  // namespace osr::test
