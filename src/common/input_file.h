// Checks on a file the user names as an input (scene, environment, weights) before it is
// opened and read whole.
#pragma once
#include <filesystem>
#include <optional>
#include <string>

namespace osr {

// Why `path` cannot be an input file, or nothing if it is a regular file (links followed).
// Devices and pipes are refused before open(): /dev/zero would be read until memory runs out
// and a pipe with no writer blocks open() forever.
inline std::optional<std::string> inputFileProblem(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) return "file not found";
  if (fs::is_directory(st)) return "is a directory";
  if (!fs::is_regular_file(st)) return "not a regular file (a device, pipe or socket)";
  return std::nullopt;
}

}  // namespace osr
