// CPU twin of the U-Net passes and of the whole network: plain loops, double accumulation,
// whole tensors and explicit concatenation (no channel-slice views), so that it shares no
// indexing code with the shaders it checks.
#pragma once
#include <cstdint>
#include <vector>

#include "nn_kernels/weights.h"

namespace osr::nn {

struct Tensor {  // NCHW fp32
  uint32_t n = 0, c = 0, h = 0, w = 0;
  std::vector<float> data;
  Tensor() = default;
  Tensor(uint32_t n_, uint32_t c_, uint32_t h_, uint32_t w_)
      : n(n_), c(c_), h(h_), w(w_), data(size_t(n_) * c_ * h_ * w_, 0.0f) {}
  float& at(uint32_t i, uint32_t ch, uint32_t y, uint32_t x) {
    return data[((size_t(i) * c + ch) * h + y) * w + x];
  }
  float at(uint32_t i, uint32_t ch, uint32_t y, uint32_t x) const {
    return data[((size_t(i) * c + ch) * h + y) * w + x];
  }
};

Tensor convCpu(const Tensor& in, const ConvWeights& conv);
Tensor maxPoolCpu(const Tensor& in);
Tensor upsampleCpu(const Tensor& in);  // bilinear x2, align_corners=False
Tensor concatCpu(const Tensor& a, const Tensor& b);  // channels of a, then b
Tensor unetCpu(const UNetWeights& weights, const Tensor& maps);  // N x 7 x 32 x 32 -> N x 3 x 32 x 32

}  // namespace osr::nn
