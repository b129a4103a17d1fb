// A check on an OpenEXR file's header before OpenEXR reads it (environment maps, the images
// osr-vk compare and the tests read).
#pragma once
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>

namespace osr {

// The largest OpenEXR image osr-vk reads: 65536 pixels a side and 16384 x 16384 in all (3 GiB of
// float RGB). The data window comes from the file, and a few bytes can claim a vast one: an
// 878-byte file claiming 16777216 x 8 pixels cost 30 s and 2.4 GB before the side limit.
inline constexpr int64_t kMaxExrSide = 65536, kMaxExrPixels = int64_t(1) << 28;

// Why a data window of w x h pixels (max - min + 1, in 64 bits) is not read, or nothing.
inline std::optional<std::string> exrDataWindowProblem(int64_t w, int64_t h) {
  if (w <= 0 || h <= 0) return "empty OpenEXR data window";
  if (w > kMaxExrSide || h > kMaxExrSide || w * h > kMaxExrPixels)
    return std::to_string(w) + " x " + std::to_string(h) + " pixels, more than osr-vk reads (" +
           std::to_string(kMaxExrSide) + " a side, " + std::to_string(kMaxExrPixels) + " in all)";
  return std::nullopt;
}

// Why OpenEXR must not open `path`, or nothing. OpenEXR 3.1 allocates each header attribute at
// the size the file states before reading it, so a 500-byte file claiming a 2 GiB attribute
// cost 2 GiB and seconds (found by tests/fuzz/fuzz_env.cpp). Walks the header (every header of
// a multi-part file) and refuses an attribute that runs past the end of the file, and a data
// window that is empty or vast (kMaxExrSide, kMaxExrPixels); a
// file that is not OpenEXR at all passes (OpenEXR says so).
inline std::optional<std::string> exrHeaderProblem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::streamoff fileSize = in.tellg();
  in.seekg(0);
  char start[8];
  if (!in.read(start, 8)) return "truncated OpenEXR header";
  uint32_t magic, version;
  std::memcpy(&magic, start, 4);
  std::memcpy(&version, start + 4, 4);
  if (magic != 20000630) return std::nullopt;  // not OpenEXR at all: OpenEXR says so
  const bool multipart = version & 0x1000;  // the version field's multi-part bit
  for (int attribute = 0;; ++attribute) {
    std::string name, type;
    if (!std::getline(in, name, '\0')) return "truncated OpenEXR header";
    if (name.empty()) {  // the end of a header; a multi-part file's list ends with an empty one
      if (!multipart || in.peek() == 0 || in.peek() == std::char_traits<char>::eof())
        return std::nullopt;
      continue;
    }
    int32_t size = 0;
    if (!std::getline(in, type, '\0') || !in.read(reinterpret_cast<char*>(&size), 4))
      return "truncated OpenEXR header";
    if (size < 0 || in.tellg() + std::streamoff(size) > fileSize)
      return "OpenEXR header attribute " + std::to_string(attribute) + " of " +
             std::to_string(size) + " bytes runs past the end of the file";
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      int32_t box[4];  // xMin, yMin, xMax, yMax
      if (!in.read(reinterpret_cast<char*>(box), 16)) return "truncated OpenEXR header";
      if (auto problem = exrDataWindowProblem(int64_t(box[2]) - box[0] + 1, int64_t(box[3]) - box[1] + 1))
        return problem;
      continue;
    }
    in.seekg(size, std::ios::cur);
  }
}

}  // namespace osr
