// What the fuzz targets (tests/fuzz/fuzz_*.cpp, docs/testing.md "Fuzzing") share: a scratch
// folder for parsers that read files by name, and the check that a refused input got what
// DESIGN.md promises bad input: one line naming the file or option.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

namespace osr::fuzz {

// A folder of this process under the system's temporary folder, emptied by clearScratch() and
// removed at exit.
inline const std::filesystem::path& scratchDir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      std::string templ = (std::filesystem::temp_directory_path() / "osr_fuzz_XXXXXX").string();
      if (!::mkdtemp(templ.data())) {
        std::perror("osr fuzz: mkdtemp");
        std::abort();
      }
      path = templ;
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

// Removes what the previous input wrote, so that every input sees the same files.
inline void clearScratch() {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(scratchDir(), ec))
    std::filesystem::remove_all(entry.path(), ec);
}

// Writes the bytes to scratchDir()/name; returns the path.
inline std::string writeScratch(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = (scratchDir() / name).string();
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!f) {
    std::fprintf(stderr, "osr fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

// A refused input's message: one non-empty line that names `name` (when given). Anything else
// aborts, which libFuzzer and the replay test report with the input.
inline void checkMessage(const std::exception& e, const std::string& name) {
  const std::string m = e.what();
  const bool oneLine = !m.empty() && m.find_first_of("\n\r") == std::string::npos;
  if (!oneLine || (!name.empty() && m.find(name) == std::string::npos)) {
    std::fprintf(stderr, "osr fuzz: the error message is not one line naming '%s': '%s'\n",
                 name.c_str(), m.c_str());
    std::abort();
  }
}

}  // namespace osr::fuzz
