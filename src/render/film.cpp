#include "render/film.h"

#include <algorithm>

#include "common/error.h"

namespace osr::render {

namespace f = gpu::film;

std::vector<float> vec4Layer(const std::vector<float>& rgb, const std::vector<float>& w) {
  const size_t n = rgb.size() / 3;
  std::vector<float> v(n * 4);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) v[4 * i + k] = rgb[3 * i + k];
    v[4 * i + 3] = w.empty() ? 0.0f : w[i];
  }
  return v;
}

void fromVec4Layer(const std::vector<float>& layer, std::vector<float>& rgb, std::vector<float>* w) {
  const size_t n = layer.size() / 4;
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) rgb[3 * i + k] = layer[4 * i + k];
    if (w) (*w)[i] = layer[4 * i + 3];
  }
}

uint64_t wholeLayerBytes(const vk::Context& ctx, uint32_t width, uint32_t height, const char* what) {
  const uint64_t bytes = uint64_t(width) * height * 16;
  if (bytes > ctx.caps().maxStorageBufferRange)
    throw DeviceError(std::string(what) + ": a " + std::to_string(width) + "x" + std::to_string(height) +
                      " layer needs " + std::to_string(bytes >> 20) +
                      " MiB, over the device's maxStorageBufferRange of " +
                      std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB");
  return bytes;
}

uint32_t windowPixels(const vk::Context& ctx, uint64_t bytesPerPixel) {
  const uint64_t fit = ctx.caps().maxStorageBufferRange / bytesPerPixel;
  const uint64_t aligned =
      std::min<uint64_t>(fit, 1u << 30) / kWindowAlignPixels * kWindowAlignPixels;
  if (aligned == 0)
    throw DeviceError("film: " + std::to_string(kWindowAlignPixels) + " pixels of " +
                      std::to_string(bytesPerPixel) +
                      " bytes exceed the device's maxStorageBufferRange of " +
                      std::to_string(ctx.caps().maxStorageBufferRange) + " bytes");
  return uint32_t(aligned);
}

Film::Film(const vk::Context& ctx, uint32_t width, uint32_t height)
    : width_(width), height_(height) {
  const uint64_t bytes = uint64_t(width) * height * sizeof(f::FilmPixel);
  // One allocation holds the whole film (bound in windows): refuse what the device cannot
  // allocate at all, naming its limit. A device limit, not bad input (the same size fits a
  // device with more memory): exit 1.
  if (bytes > ctx.caps().maxMemoryAllocationSize)
    throw DeviceError("film: " + std::to_string(width) + "x" + std::to_string(height) + " needs " +
                      std::to_string(bytes >> 20) +
                      " MiB, over the device's maxMemoryAllocationSize of " +
                      std::to_string(ctx.caps().maxMemoryAllocationSize >> 20) + " MiB");
  buffer_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "pt film");
}

vk::BufferRange Film::window(uint32_t first, uint32_t count) const {
  return vk::BufferRange(buffer_, VkDeviceSize(first) * sizeof(f::FilmPixel),
                         VkDeviceSize(count) * sizeof(f::FilmPixel));
}

void Film::recordClear(VkCommandBuffer cmd) const {
  vkCmdFillBuffer(cmd, buffer_.handle(), 0, VK_WHOLE_SIZE, 0u);
  vk::transferBarrier(cmd);
}

void FilmLayers::allocate(int w, int h) {
  width = w;
  height = h;
  const size_t n = size_t(w) * size_t(h);
  for (auto* v : {&combined, &direct, &indirect, &albedo, &normal}) v->resize(n * 3);
  depth.resize(n);
  variance.resize(n);
  light.resize(n);
}

void estimateVarianceFromNeighbours(FilmLayers& f) {
  const size_t n = size_t(f.width) * size_t(f.height);
  std::vector<float> lum(n);
  for (size_t i = 0; i < n; ++i)
    lum[i] = 0.2126f * f.combined[3 * i] + 0.7152f * f.combined[3 * i + 1] +
             0.0722f * f.combined[3 * i + 2];
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      double sum = 0.0, sumSq = 0.0;
      int count = 0;
      for (int qy = std::max(y - 1, 0); qy <= std::min(y + 1, f.height - 1); ++qy)
        for (int qx = std::max(x - 1, 0); qx <= std::min(x + 1, f.width - 1); ++qx) {
          const double l = lum[size_t(qy) * size_t(f.width) + size_t(qx)];
          sum += l;
          sumSq += l * l;
          ++count;
        }
      const double var = count > 1 ? (sumSq - sum * sum / count) / (count - 1) : 0.0;
      f.variance[size_t(y) * size_t(f.width) + size_t(x)] = float(std::max(var, 0.0));
    }
}

void upsampleBilinear(const FilmLayers& from, FilmLayers& into) {
  into.allocate(into.width, into.height);
  into.samples = from.samples;
  into.droppedSamples = from.droppedSamples;
  into.noisy.resize(from.noisy.empty() ? 0 : into.combined.size());
  // Each output pixel's centre in the source's pixel coordinates, and its two neighbours and
  // weight along one axis (clamped at the borders).
  struct Tap {
    int i0, i1;
    float w1;
  };
  const auto taps = [](int out, int in) {
    std::vector<Tap> t(static_cast<size_t>(out));
    for (int o = 0; o < out; ++o) {
      const float c =
          std::clamp((float(o) + 0.5f) * float(in) / float(out) - 0.5f, 0.f, float(in - 1));
      const int i0 = int(c);
      t[size_t(o)] = {i0, std::min(i0 + 1, in - 1), c - float(i0)};
    }
    return t;
  };
  const std::vector<Tap> tx = taps(into.width, from.width), ty = taps(into.height, from.height);
  // Colour is interpolated as x / (1 + |x|), so a lamp's radiance does not spread into the
  // pixels round it (linear interpolation's halo held 95 % of the error of a 4x upsampled
  // room against its reference: relMSE 0.21, 0.026 this way).
  const auto compress = [](float x) { return x / (1.f + std::abs(x)); };
  const auto expand = [](float y) { return y / std::max(1.f - std::abs(y), 1e-6f); };
  const auto resize = [&](const std::vector<float>& src, std::vector<float>& dst, int channels,
                          bool colour = false) {
    for (int y = 0; y < into.height; ++y) {
      const Tap v = ty[size_t(y)];
      for (int x = 0; x < into.width; ++x) {
        const Tap u = tx[size_t(x)];
        const auto at = [&](int sx, int sy, int c) {
          const float v = src[(size_t(sy) * size_t(from.width) + size_t(sx)) * channels + c];
          return colour ? compress(v) : v;
        };
        for (int c = 0; c < channels; ++c) {
          const float top = at(u.i0, v.i0, c) + u.w1 * (at(u.i1, v.i0, c) - at(u.i0, v.i0, c));
          const float bottom = at(u.i0, v.i1, c) + u.w1 * (at(u.i1, v.i1, c) - at(u.i0, v.i1, c));
          const float value = top + v.w1 * (bottom - top);
          dst[(size_t(y) * size_t(into.width) + size_t(x)) * channels + c] =
              colour ? expand(value) : value;
        }
      }
    }
  };
  resize(from.combined, into.combined, 3, true);
  resize(from.direct, into.direct, 3, true);
  resize(from.indirect, into.indirect, 3, true);
  resize(from.albedo, into.albedo, 3);
  resize(from.normal, into.normal, 3);
  resize(from.depth, into.depth, 1);
  resize(from.variance, into.variance, 1);
  resize(from.light, into.light, 1);
  if (!from.noisy.empty()) resize(from.noisy, into.noisy, 3, true);
}

FilmLayers Film::resolve() const {
  FilmLayers out;
  resolve(out);
  return out;
}

void Film::resolve(FilmLayers& out) const {
  out.allocate(int(width_), int(height_));
  out.samples = 0;
  out.droppedSamples = 0;
  out.noisy.clear();  // a denoiser's copy of an earlier colour (its capacity is kept)
  const size_t n = pixelCount();
  // Downloaded in chunks through one small buffer, not as a copy of the whole film: at 4K the
  // film is 760 MiB, and fresh host memory costs page faults on a CPU device
  // (docs/device_notes.md, "What lavapipe charges for").
  constexpr size_t kChunkPixels = size_t(1) << 16;
  std::vector<gpu::film::FilmPixel> px;
  for (size_t first = 0; first < n; first += kChunkPixels) {
    const size_t count = std::min(kChunkPixels, n - first);
    px.resize(count);
    buffer_.download(px.data(), count * sizeof(gpu::film::FilmPixel),
                     first * sizeof(gpu::film::FilmPixel));
    if (first == 0) out.samples = uint32_t(px[0].combined.w + 0.5f);
    for (size_t j = 0; j < count; ++j) {
      const gpu::film::FilmPixel& p = px[j];
      const size_t i = first + j;
      const float inv = p.combined.w > 0.f ? 1.f / p.combined.w : 0.f;
      for (int c = 0; c < 3; ++c) {
        out.combined[i * 3 + c] = p.combined[c] * inv;
        out.direct[i * 3 + c] = p.direct[c] * inv;
        out.indirect[i * 3 + c] = p.indirect[c] * inv;
        out.albedo[i * 3 + c] = p.albedo[c] * inv;
        out.normal[i * 3 + c] = p.normal[c] * inv;
      }
      out.light[i] = p.albedo.w * inv;
      out.depth[i] = p.depth.y > 0.f ? p.depth.x / p.depth.y : 0.f;
      const double samples = p.combined.w;
      const double lum = 0.2126 * out.combined[i * 3] + 0.7152 * out.combined[i * 3 + 1] +
                         0.0722 * out.combined[i * 3 + 2];
      const double var = samples > 1.5
                             ? (p.depth.z - samples * lum * lum) / (samples * (samples - 1.0))
                             : p.depth.z - lum * lum;
      out.variance[i] = float(std::max(var, 0.0));
      out.droppedSamples += uint64_t(p.normal.w);
    }
  }
}

}  // namespace osr::render
