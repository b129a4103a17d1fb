// Test helper: runs the built osr-vk (OSR_BINARY_DIR from the environment, else the build's)
// through the shell and captures its exit code and its stdout + stderr.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
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

}  // namespace osr::test
