// A check on a Radiance .hdr image before stb_image decodes it (environment maps, and any
// image of a glTF, since stb_image recognizes the format by its content, not by its name).
#pragma once
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include "common/exr_header.h"

namespace osr {

// Why stb_image would not finish decoding these bytes as a Radiance .hdr, or nothing (also for
// bytes that are not one, and for a file stb_image refuses by itself): more pixels than
// osr-vk reads, or a scanline it would loop on. Debian's stb_image
// (2.27) reads a run-length scanline until it has `width` values per channel, and a run or dump
// of length 0 adds none: a zero byte there, or the end of a truncated file (which reads as
// zeros), makes it loop forever. This walks the scanlines as stbi__hdr_load does.
inline std::optional<std::string> radianceHdrProblem(const unsigned char* data, size_t size) {
  size_t at = 0;
  auto next = [&]() -> unsigned { return at < size ? data[at++] : 0u; };
  // stbi__hdr_gettoken: up to a newline (a line's last byte at the end of the file is dropped),
  // at most 1023 characters, read as a C string (a NUL ends it: a line that starts with one is
  // the empty line that ends the header).
  auto line = [&] {
    std::string text;
    for (unsigned c = next(); at < size && c != '\n'; c = next()) {
      text += char(c);
      if (text.size() == 1023) {
        while (at < size && next() != '\n') {
        }
        break;
      }
    }
    return text.substr(0, text.find('\0'));
  };
  const std::string magic = line();
  if (magic != "#?RADIANCE" && magic != "#?RGBE") return std::nullopt;
  while (at < size && !line().empty()) {
  }
  const std::string resolution = line();
  if (resolution.compare(0, 3, "-Y ") != 0) return std::nullopt;
  char* end = nullptr;
  const long height = std::strtol(resolution.c_str() + 3, &end, 10);
  while (*end == ' ') ++end;
  if (std::strncmp(end, "+X ", 3) != 0) return std::nullopt;
  const long width = std::strtol(end + 3, nullptr, 10);
  if (width <= 0 || height <= 0) return std::nullopt;  // stb_image refuses it
  // The OpenEXR readers' bound: a 138-byte file claiming 5555555 x 8 pixels took over 10 s.
  if (auto problem = exrDataWindowProblem(width, height)) return problem;
  // stb_image reads other widths, and scanlines that do not start 2 2, pixel by pixel.
  if (width < 8 || width >= 32768) return std::nullopt;
  for (long y = 0; y < height; ++y) {
    const unsigned c1 = next(), c2 = next(), high = next();
    if (c1 != 2 || c2 != 2 || (high & 0x80) != 0) return std::nullopt;
    if (long((high << 8) | next()) != width) return std::nullopt;
    for (int channel = 0; channel < 4; ++channel) {
      for (long x = 0; x < width;) {
        if (at >= size) return "truncated Radiance .hdr (scanline " + std::to_string(y) + " ends early)";
        unsigned count = next();
        const bool run = count > 128;
        if (run) count -= 128;
        if (count == 0)
          return "corrupt Radiance .hdr (a run of length 0 in scanline " + std::to_string(y) + ")";
        if (long(count) > width - x) return std::nullopt;
        at += run ? 1 : count;
        x += count;
      }
    }
  }
  return std::nullopt;
}

}  // namespace osr
