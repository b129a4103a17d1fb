// Checks on a path the user names as an input file (scene, environment, weights) before it is
// opened and read whole, or as an output folder before anything is written.
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
  if (ec && ec != std::errc::no_such_file_or_directory) return ec.message();  // e.g. too long
  if (!fs::exists(st)) return "file not found";
  if (fs::is_directory(st)) return "is a directory";
  if (!fs::is_regular_file(st)) return "not a regular file (a device, pipe or socket)";
  return std::nullopt;
}

// Why `path` cannot be an output folder that is made if missing (" exists and is not a folder",
// or the system's reason, e.g. a name too long), or nothing if it is a folder or does not exist.
inline std::optional<std::string> folderProblem(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) return ": " + ec.message();
  if (fs::exists(st) && !fs::is_directory(st)) return std::string(" exists and is not a folder");
  return std::nullopt;
}

}  // namespace osr
