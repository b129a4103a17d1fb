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

// The value's size in bytes of OpenEXR's attribute types that OpenEXR reads by their type,
// not by the size the file states (OpenEXR 3.1, TypedAttribute<T>::readValueFrom), or 0.
inline int32_t exrFixedValueSize(const std::string& type) {
  static const struct {
    const char* type;
    int32_t size;
  } kTypes[] = {{"box2i", 16},  {"box2f", 16},  {"chromaticities", 32}, {"compression", 1},
                {"double", 8},  {"envmap", 1},  {"float", 4},           {"int", 4},
                {"keycode", 28}, {"lineOrder", 1}, {"m33f", 36},        {"m33d", 72},
                {"m44f", 64},   {"m44d", 128},  {"rational", 8},        {"tiledesc", 9},
                {"timecode", 8}, {"v2i", 8},    {"v2f", 8},             {"v2d", 16},
                {"v3i", 12},    {"v3f", 12},    {"v3d", 24},            {"deepImageState", 1}};
  for (const auto& t : kTypes)
    if (type == t.type) return t.size;
  return 0;
}

// Why OpenEXR must not open `path`, or nothing. OpenEXR 3.1 allocates an attribute at the size
// the file states before reading it, so a 500-byte file claiming a 2 GiB attribute cost 2 GiB
// and seconds (found by tests/fuzz/fuzz_env.cpp). This walks the header as OpenEXR reads it
// (every header of a multi-part file) and refuses an attribute that runs past the end of the
// file, a data window that is empty or vast (kMaxExrSide, kMaxExrPixels), and anything that
// would make OpenEXR's reading and this walk part ways: OpenEXR reads a channel list, a
// preview and the fixed-size types by their content, whatever size the file states, so a
// wrong size there let a later attribute hide from the walk (tests/fuzz/fuzz_exr.cpp found
// one claiming 1.8 GB behind a channel list 12 bytes longer than stated), and it stops a name
// at 255 characters. A file that is not OpenEXR at all passes (OpenEXR says so).
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
  constexpr size_t kMaxName = 255;          // OpenEXR's Name::MAX_LENGTH
  const auto readName = [&](std::string& out) {
    return std::getline(in, out, '\0') && out.size() <= kMaxName;
  };
  for (int attribute = 0;; ++attribute) {
    const std::string which = "OpenEXR header attribute " + std::to_string(attribute);
    std::string name, type;
    if (!readName(name)) return "truncated OpenEXR header or a name over 255 characters";
    if (name.empty()) {  // the end of a header; a multi-part file's list ends with an empty one
      if (!multipart || in.peek() == 0 || in.peek() == std::char_traits<char>::eof())
        return std::nullopt;
      continue;
    }
    int32_t size = 0;
    if (!readName(type) || !in.read(reinterpret_cast<char*>(&size), 4))
      return "truncated OpenEXR header or a name over 255 characters";
    const std::streamoff valueStart = in.tellg();
    if (size < 0 || valueStart + std::streamoff(size) > fileSize)
      return which + " of " + std::to_string(size) + " bytes runs past the end of the file";
    const int32_t fixed = exrFixedValueSize(type);
    if (fixed && size != fixed)
      return which + " (" + type + ") states " + std::to_string(size) + " bytes, not " +
             std::to_string(fixed);
    if (type == "chlist") {  // channels: a name and 16 bytes each, up to an empty name
      std::string channel;
      while (readName(channel) && !channel.empty()) in.seekg(16, std::ios::cur);
      if (!in || in.tellg() - valueStart != size)
        return which + " (chlist) does not hold the " + std::to_string(size) + " bytes it states";
      continue;
    }
    if (type == "preview") {  // width, height, then 4 bytes a pixel
      uint32_t wh[2];
      if (size < 8 || !in.read(reinterpret_cast<char*>(wh), 8) ||
          8 + 4 * uint64_t(wh[0]) * wh[1] != uint64_t(size))
        return which + " (preview) does not hold the " + std::to_string(size) + " bytes it states";
      in.seekg(size - 8, std::ios::cur);
      continue;
    }
    if (name == "dataWindow" && type == "box2i") {
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
