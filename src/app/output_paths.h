// What osr-vk will write, checked before any work: an output may not be any file the run
// reads (scene, its buffers and textures, environment, weights) nor another output, judged by
// file identity (device and inode) so that a symlink, a hard link or another spelling of the
// same path is caught; its name's extension must be the format written; its directory must be
// writable. Everything is refused as one InputError line (exit 2) before rendering.
#pragma once
#include <string>
#include <vector>

namespace osr::app {

struct NamedPath {
  std::string role;  // "--offline", "the scene", "--env", ... as the message names it
  std::string path;
};

struct OutputFile {
  std::string role;       // the option, e.g. "--offline"
  std::string path;
  std::string extension;  // lower case with the dot, e.g. ".exr"
  std::string format;     // what is written, e.g. "OpenEXR"
};

// Throws InputError if an output is an input or another output (same file), has a name
// whose extension differs from its format, or cannot be created (image::checkWritable).
void checkOutputs(const std::vector<OutputFile>& outputs, const std::vector<NamedPath>& inputs);

// Whether a and b name the same file: by device and inode where both exist; where one does
// not exist yet, by the identity of their parent directories and the same final name.
bool sameFile(const std::string& a, const std::string& b);

}  // namespace osr::app
