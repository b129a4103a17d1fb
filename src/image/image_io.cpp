#include "image/image_io.h"

#include <ImfAttribute.h>
#include <ImfChannelList.h>
#include <ImfFloatAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfThreading.h>
#include <half.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include "common/error.h"
#include "common/exr_header.h"

namespace osr::image {

namespace fs = std::filesystem;

namespace {

std::string tempNameFor(const std::string& path) {
  return path + ".tmp" + std::to_string(::getpid());
}

// pendingTempFile(): the name is complete before `pendingReady` says so, so a handler never
// reads half a name (which could be a prefix such as the output's own name).
char pendingName[4096];
std::atomic<bool> pendingReady{false};
static_assert(std::atomic<bool>::is_always_lock_free);

// Marks `tmp` as the temporary being written (until commit or discard).
void markPending(const std::string& tmp) {
  pendingReady = false;
  if (tmp.size() >= sizeof pendingName) return;  // not removable by a handler; still renamed
  std::memcpy(pendingName, tmp.c_str(), tmp.size() + 1);
  pendingReady = true;
}

// Removes a temporary that will not become the output.
void discard(const std::string& tmp) {
  pendingReady = false;
  std::error_code ec;
  fs::remove(tmp, ec);
}

// Renames the finished temporary over the target; on failure removes the temporary. A
// handler that unlinks the pending name during the rename leaves either the old output or
// the new complete one.
void commit(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  pendingReady = false;
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path + ": cannot write (" + ec.message() + ")");
  }
}

}  // namespace

const char* pendingTempFile() { return pendingReady ? pendingName : nullptr; }

void checkWritable(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path + ": is a directory");
  std::string tmp = tempNameFor(path);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  std::fclose(f);
  fs::remove(tmp, ec);
}

void writeFileAtomic(const std::string& path, const void* data, size_t bytes) {
  const std::string tmp = tempNameFor(path);
  markPending(tmp);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) {
    const std::string why = std::strerror(errno);
    discard(tmp);
    throw InputError(path + ": cannot write (" + why + ")");
  }
  const bool ok = std::fwrite(data, 1, bytes, f) == bytes;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    const std::string why = std::strerror(errno);
    discard(tmp);
    throw InputError(path + ": cannot write (" + why + ")");
  }
  commit(tmp, path);
}

void writeExr(const std::string& path, const LayeredImage& image, ExrPixelType type) {
  const int w = image.width, h = image.height;
  const Imf::PixelType pt = type == ExrPixelType::Half ? Imf::HALF : Imf::FLOAT;
  Imf::Header header(w, h);
  header.compression() = Imf::ZIP_COMPRESSION;
  // Channels in file order, each a layer's interleaved component.
  struct Channel {
    std::string name;
    const float* data;  // first pixel's value
    size_t stride;      // floats from one pixel to the next
  };
  std::vector<Channel> channels;
  for (const ImageLayer& layer : image.layers) {
    const size_t nc = layer.channelNames.size();
    if (layer.data.size() != size_t(w) * h * nc)
      throw std::logic_error("writeExr: layer '" + layer.name + "' has the wrong size");
    for (size_t c = 0; c < nc; ++c) {
      std::string name =
          layer.name.empty() ? layer.channelNames[c] : layer.name + "." + layer.channelNames[c];
      header.channels().insert(name, Imf::Channel(pt));
      channels.push_back({name, layer.data.data() + c, nc});
    }
  }
  for (const ExrAttribute& a : image.attributes) {
    if (const int* i = std::get_if<int>(&a.value))
      header.insert(a.name, Imf::IntAttribute(*i));
    else if (const float* f = std::get_if<float>(&a.value))
      header.insert(a.name, Imf::FloatAttribute(*f));
    else
      header.insert(a.name, Imf::StringAttribute(std::get<std::string>(a.value)));
  }
  const std::string tmp = tempNameFor(path);
  markPending(tmp);
  try {
    // ZIP compression of a 4K multi-layer image takes seconds per core: use them all.
    Imf::OutputFile file(tmp.c_str(), header, int(std::max(1u, std::thread::hardware_concurrency())));
    if (pt == Imf::FLOAT) {
      // Float channels are read from the layers' interleaved floats in place.
      Imf::FrameBuffer fb;
      for (const Channel& c : channels) {
        // OpenEXR's slices take non-const memory; writing only reads it.
        char* base = const_cast<char*>(reinterpret_cast<const char*>(c.data));
        fb.insert(c.name, Imf::Slice(Imf::FLOAT, base, sizeof(float) * c.stride,
                                     sizeof(float) * c.stride * w));
      }
      file.setFrameBuffer(fb);
      file.writePixels(h);
    } else {
      // OpenEXR 3.1 writes half channels only from half memory: convert a band of rows at a
      // time into one buffer, not the whole image (hundreds of MiB at 4K, each page a fault
      // on first touch).
      const int bandRows = std::max(1, std::min(h, int((size_t(8) << 20) / (channels.size() * sizeof(half) * w))));
      std::vector<half> band(channels.size() * size_t(bandRows) * w);
      for (int y0 = 0; y0 < h; y0 += bandRows) {
        const int rows = std::min(bandRows, h - y0);
        Imf::FrameBuffer fb;
        for (size_t k = 0; k < channels.size(); ++k) {
          half* plane = band.data() + k * size_t(bandRows) * w;
          const Channel& c = channels[k];
          for (size_t i = 0; i < size_t(rows) * w; ++i)
            plane[i] = half(c.data[(size_t(y0) * w + i) * c.stride]);
          // The slice addresses row y at plane + (y - y0) * w.
          char* base = reinterpret_cast<char*>(plane) - ptrdiff_t(y0) * w * ptrdiff_t(sizeof(half));
          fb.insert(c.name, Imf::Slice(Imf::HALF, base, sizeof(half), sizeof(half) * w));
        }
        file.setFrameBuffer(fb);
        file.writePixels(rows);
      }
    }
  } catch (const std::exception& e) {
    discard(tmp);
    throw InputError(path + ": cannot write OpenEXR (" + oneLine(e.what()) + ")");
  }
  commit(tmp, path);
}

RgbImage readExrRgb(const std::string& path, const std::string& layer) {
  if (auto problem = exrHeaderProblem(path)) throw InputError(path + ": " + *problem);
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    RgbImage img;  // exrHeaderProblem has refused an empty or vast data window
    img.width = dw.max.x - dw.min.x + 1;
    img.height = dw.max.y - dw.min.y + 1;
    img.rgb.assign(size_t(img.width) * img.height * 3, 0.f);
    const Imf::ChannelList& ch = file.header().channels();
    const std::string prefix = layer.empty() ? "" : layer + ".";
    const std::string names[3] = {prefix + "R", prefix + "G", prefix + "B"}, y = prefix + "Y";
    bool rgb = ch.findChannel(names[0]) && ch.findChannel(names[1]) && ch.findChannel(names[2]);
    bool grey = ch.findChannel(y);
    if (!rgb && !grey)
      throw InputError(path + ": no R, G, B (or Y) channels in the " +
                       (layer.empty() ? std::string("default layer") : "layer '" + layer + "'"));
    Imf::FrameBuffer fb;
    // Slice::Make places the data window's origin at the buffer's start without pointing
    // outside it (the classic base - origin pointer is undefined for a window far from 0: found
    // by tests/fuzz/fuzz_exr.cpp under UBSan). A grey image reads Y into the R slot once, then
    // copies it to G and B.
    for (int c = 0; c < (rgb ? 3 : 1); ++c)
      fb.insert(rgb ? names[c] : y, Imf::Slice::Make(Imf::FLOAT, img.rgb.data() + c, dw, 3 * sizeof(float),
                                                       3 * sizeof(float) * size_t(img.width)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    if (!rgb)
      for (size_t i = 0; i < img.rgb.size(); i += 3) img.rgb[i + 1] = img.rgb[i + 2] = img.rgb[i];
    return img;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read OpenEXR (" + oneLine(e.what()) + ")");
  }
}

std::set<std::string> exrChannels(const std::string& path) {
  if (auto problem = exrHeaderProblem(path)) throw InputError(path + ": " + *problem);
  try {
    Imf::InputFile file(path.c_str());
    std::set<std::string> names;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
      names.insert(it.name());
    return names;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read OpenEXR (" + oneLine(e.what()) + ")");
  }
}

std::vector<ExrAttribute> readExrAttributes(const std::string& path) {
  if (auto problem = exrHeaderProblem(path)) throw InputError(path + ": " + *problem);
  try {
    Imf::InputFile file(path.c_str());
    std::vector<ExrAttribute> out;
    for (auto it = file.header().begin(); it != file.header().end(); ++it) {
      const Imf::Attribute& a = it.attribute();
      if (auto* i = dynamic_cast<const Imf::IntAttribute*>(&a))
        out.push_back({it.name(), i->value()});
      else if (auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a))
        out.push_back({it.name(), f->value()});
      else if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&a))
        out.push_back({it.name(), s->value()});
    }
    return out;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read OpenEXR (" + oneLine(e.what()) + ")");
  }
}

bool isCompleteImage(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".exr") {
    try {
      readExrRgb(path);  // every scanline block: a cut file fails here
      return true;
    } catch (const InputError&) {
      return false;
    }
  }
  if (ext == ".png") {
    int w = 0, h = 0, n = 0;
    unsigned char* pixels = stbi_load(path.c_str(), &w, &h, &n, 0);
    stbi_image_free(pixels);
    return pixels != nullptr;
  }
  return false;
}

double meteredLuminance(const RgbImage& image, const std::vector<float>& depth) {
  std::vector<double> metered, lit;
  for (size_t i = 0; i < image.rgb.size() / 3; ++i) {
    double v = image.luminance(i);
    if (!std::isfinite(v) || v < 0.0) continue;
    const bool hit = i < depth.size() && depth[i] > 0.f;
    if (hit || v > 0.0) metered.push_back(v);
    if (v > 0.0) lit.push_back(v);
  }
  if (lit.empty()) return 0.0;
  std::nth_element(lit.begin(), lit.begin() + lit.size() / 2, lit.end());
  const double clip = kMeterClipOverMedian * lit[lit.size() / 2];
  double sum = 0.0;
  for (double v : metered) sum += std::min(v, clip);
  return sum / double(metered.size());
}

double autoExposureEv(const RgbImage& image, const std::vector<float>& depth) {
  const double metered = meteredLuminance(image, depth);
  return metered > 0.0 ? std::log2(kExposureKey / metered) : 0.0;
}

namespace {
uint8_t srgb8(float x) {
  float s = x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(s * 255.f));
}

float toneMapped(float x, ToneMap op) {
  if (!std::isfinite(x) || x < 0.f) return 0.f;
  switch (op) {
    case ToneMap::Reinhard:
      return x / (1.f + x);
    case ToneMap::Aces:
      return std::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.f, 1.f);
    case ToneMap::Clamp:
      break;
  }
  return std::min(x, 1.f);
}
}  // namespace

const char* toneMapName(ToneMap op) {
  switch (op) {
    case ToneMap::Reinhard:
      return "reinhard";
    case ToneMap::Aces:
      return "aces";
    case ToneMap::Clamp:
      break;
  }
  return "clamp";
}

std::vector<uint8_t> toneMapSrgb8(const RgbImage& image, double exposureEv, ToneMap op) {
  const float scale = float(std::exp2(exposureEv));
  std::vector<uint8_t> px(image.rgb.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = srgb8(toneMapped(image.rgb[i] * scale, op));
  return px;
}

void writePng8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  const std::string tmp = tempNameFor(path);
  markPending(tmp);
  if (!stbi_write_png(tmp.c_str(), width, height, 3, rgb.data(), width * 3)) {
    discard(tmp);
    throw InputError(path + ": cannot write PNG");
  }
  commit(tmp, path);
}

void writePng(const std::string& path, const RgbImage& image, std::optional<double> exposureEv,
              const std::vector<float>& depth, ToneMap op) {
  writePng8(path, image.width, image.height,
            toneMapSrgb8(image, exposureEv ? *exposureEv : autoExposureEv(image, depth), op));
}

}  // namespace osr::image
