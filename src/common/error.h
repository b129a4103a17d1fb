// Error kinds that map onto the process exit codes of DESIGN.md: InputError (bad scene,
// weights, arguments) exits 2, everything else (DeviceError, internal) exits 1. Messages are
// one line naming what and where, e.g. "scene.gltf: accessor 3 reads past buffer 0".
#pragma once
#include <stdexcept>
#include <string>

namespace osr {

// `text` with its control characters written as escapes (\r, \n, \t, \xNN), so that a message
// quoting what the user gave stays one printable line: an argument from a script saved with
// CRLF line ends ends in '\r', which would send the rest of the line back over its start.
inline std::string escapeControls(const std::string& text) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '\r') out += "\\r";
    else if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (u < 0x20 || u == 0x7f) out += std::string("\\x") + kHex[u >> 4] + kHex[u & 15];
    else out += c;
  }
  return out;
}

// The user's input is wrong: a file, a flag, a value. Exit code 2. The message is one line
// whatever it quotes (escapeControls).
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(escapeControls(what)) {}
  explicit InputError(const char* what) : InputError(std::string(what)) {}
};

// The Vulkan device or driver failed, or a device limit was exceeded. Exit code 1.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A library's message (tinygltf's, OpenEXR's) as one printable line for an error: they span
// lines and may quote raw bytes of a broken file (a channel name with a newline in it).
inline std::string oneLine(const std::string& text) {
  std::string out;
  bool space = false;
  for (char c : text) {
    if (static_cast<unsigned char>(c) >= 0x80 ||
        (c != '\n' && c != '\r' && (c < 0x20 || c == 0x7f)))
      c = '?';
    if (c == '\n' || c == '\r') {
      space = !out.empty();
      continue;
    }
    if (space) out += "; ";
    space = false;
    out += c;
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return out;
}

inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitBadInput = 2;

}  // namespace osr
