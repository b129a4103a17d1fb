#include "common/test_paths.h"

#include <unistd.h>

namespace osr::test {

std::string dataPath(const std::string& name) { return std::string(OSR_TEST_DATA_DIR) + "/" + name; }

std::filesystem::path tempDir(const std::string& tag) {
  std::filesystem::path d = std::filesystem::temp_directory_path() /
                            ("osr_test_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

std::string referencePath(const std::string& name) {
  return std::string(OSR_REFERENCE_DIR) + "/" + name;
}

}  // namespace osr::test
