// Helpers of the nn_kernels tests: random tensors, fp32 / packed-fp16 device buffers, and the
// error measure max|gpu - cpu| / max|cpu| used by every comparison (printed on failure).
#pragma once
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "nn_kernels/unet_cpu.h"
#include "nn_kernels/weights.h"
#include "vk/buffer.h"

namespace osr::test {

inline nn::Tensor randomTensor(uint32_t n, uint32_t c, uint32_t h, uint32_t w, uint32_t seed,
                               bool roundHalf = false) {
  nn::Tensor t(n, c, h, w);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  for (float& v : t.data) v = roundHalf ? nn::halfToFloat(nn::floatToHalf(uni(rng))) : uni(rng);
  return t;
}

// Device buffer holding `values` as fp32 words or packed fp16 pairs (plus 256 spare bytes).
inline vk::Buffer deviceTensor(const vk::Context& ctx, const std::vector<float>& values, bool half,
                               const char* name, VkBufferUsageFlags extraUsage = 0) {
  std::vector<uint32_t> words;
  if (half) {
    words.assign((values.size() + 1) / 2, 0);
    for (size_t i = 0; i < values.size(); ++i)
      words[i / 2] |= uint32_t(nn::floatToHalf(values[i])) << (16 * (i % 2));
  } else {
    words.resize(values.size());
    std::memcpy(words.data(), values.data(), values.size() * 4);
  }
  vk::Buffer b(ctx, words.size() * 4 + 256, vk::MemoryUse::DeviceLocal, name, extraUsage);
  b.uploadVector(words);
  return b;
}

inline std::vector<float> readTensor(const vk::Buffer& b, size_t count, bool half) {
  std::vector<float> out(count);
  if (half) {
    auto words = b.downloadVector<uint32_t>((count + 1) / 2);
    for (size_t i = 0; i < count; ++i) out[i] = nn::halfToFloat(uint16_t(words[i / 2] >> (16 * (i % 2))));
  } else {
    out = b.downloadVector<float>(count);
  }
  return out;
}

inline double maxAbs(const std::vector<float>& v) {
  double m = 0;
  for (float x : v) m = std::max(m, double(std::fabs(x)));
  return m;
}

inline double maxAbsDiff(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    double d = std::fabs(double(a[i]) - double(b[i]));
    if (!(d <= m)) m = std::isnan(d) ? INFINITY : d;
  }
  return m;
}

// max|a - ref| / max|ref| (ref all zero: absolute).
inline double relError(const std::vector<float>& a, const std::vector<float>& ref) {
  return maxAbsDiff(a, ref) / std::max(maxAbs(ref), 1e-30);
}

}  // namespace osr::test
