// Error kinds that map onto the process exit codes of DESIGN.md: InputError (bad scene,
// weights, arguments) exits 2, everything else (DeviceError, internal) exits 1. Messages are
// one line naming what and where, e.g. "scene.gltf: accessor 3 reads past buffer 0".
#pragma once
#include <stdexcept>
#include <string>

namespace osr {

// The user's input is wrong: a file, a flag, a value. Exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The Vulkan device or driver failed, or a device limit was exceeded. Exit code 1.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitBadInput = 2;

}  // namespace osr
