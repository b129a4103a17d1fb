#include "common/test_paths.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <stdexcept>

namespace osr::test {

std::string sourcePath(const std::string& name) {
  const char* env = std::getenv("OSR_SOURCE_DIR");
  return std::string(env && *env ? env : OSR_SOURCE_DIR) + "/" + name;
}

std::string dataPath(const std::string& name) { return sourcePath("tests/data/" + name); }

std::filesystem::path tempDir(const std::string& tag) {
  std::filesystem::path d = std::filesystem::temp_directory_path() /
                            ("osr_test_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

std::string makeFifo(const std::string& tag, const std::string& name) {
  const std::string path = (tempDir(tag) / name).string();
  ::unlink(path.c_str());
  if (::mkfifo(path.c_str(), 0600) != 0) throw std::runtime_error(path + ": mkfifo failed");
  return path;
}

std::string referencePath(const std::string& name) {
  return sourcePath("scenes/" + name);
}

}  // namespace osr::test
