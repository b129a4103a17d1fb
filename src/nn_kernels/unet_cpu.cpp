#include "nn_kernels/unet_cpu.h"

#include <algorithm>
#include <cmath>

namespace osr::nn {

Tensor convCpu(const Tensor& in, const ConvWeights& conv) {
  Tensor out(in.n, conv.cout, in.h, in.w);
  const int k = int(conv.kernel), pad = k / 2;
  std::vector<double> acc(size_t(in.h) * in.w);
  for (uint32_t i = 0; i < in.n; ++i)
    for (uint32_t co = 0; co < conv.cout; ++co) {
      std::fill(acc.begin(), acc.end(), double(conv.bias[co]));
      for (uint32_t ci = 0; ci < conv.cin; ++ci)
        for (int ky = 0; ky < k; ++ky)
          for (int kx = 0; kx < k; ++kx) {
            const double w = conv.weight[((size_t(co) * conv.cin + ci) * k + ky) * k + kx];
            for (int y = 0; y < int(in.h); ++y) {
              const int iy = y + ky - pad;
              if (iy < 0 || iy >= int(in.h)) continue;
              for (int x = 0; x < int(in.w); ++x) {
                const int ix = x + kx - pad;
                if (ix < 0 || ix >= int(in.w)) continue;
                acc[size_t(y) * in.w + x] += w * in.at(i, ci, iy, ix);
              }
            }
          }
      for (uint32_t y = 0; y < in.h; ++y)
        for (uint32_t x = 0; x < in.w; ++x) {
          double v = acc[size_t(y) * in.w + x];
          if (conv.activation == Activation::LeakyRelu && v < 0) v *= conv.slope;
          if (conv.activation == Activation::Relu) v = std::max(v, 0.0);
          if (conv.batchNorm) v = v * conv.scale[co] + conv.shift[co];
          out.at(i, co, y, x) = float(v);
        }
    }
  return out;
}

Tensor maxPoolCpu(const Tensor& in) {
  Tensor out(in.n, in.c, in.h / 2, in.w / 2);
  for (uint32_t i = 0; i < in.n; ++i)
    for (uint32_t c = 0; c < in.c; ++c)
      for (uint32_t y = 0; y < out.h; ++y)
        for (uint32_t x = 0; x < out.w; ++x)
          out.at(i, c, y, x) = std::max({in.at(i, c, 2 * y, 2 * x), in.at(i, c, 2 * y, 2 * x + 1),
                                         in.at(i, c, 2 * y + 1, 2 * x), in.at(i, c, 2 * y + 1, 2 * x + 1)});
  return out;
}

Tensor upsampleCpu(const Tensor& in) {
  // PyTorch upsample_bilinear2d, align_corners=False, scale 2: src = 0.5 * (dst + 0.5) - 0.5.
  Tensor out(in.n, in.c, in.h * 2, in.w * 2);
  auto src = [](uint32_t dst, uint32_t size, uint32_t& i0, uint32_t& i1, double& l1) {
    double s = std::max(0.5 * (dst + 0.5) - 0.5, 0.0);
    i0 = uint32_t(s);
    i1 = std::min(i0 + 1, size - 1);
    l1 = s - i0;
  };
  for (uint32_t i = 0; i < in.n; ++i)
    for (uint32_t c = 0; c < in.c; ++c)
      for (uint32_t y = 0; y < out.h; ++y)
        for (uint32_t x = 0; x < out.w; ++x) {
          uint32_t y0, y1, x0, x1;
          double ly, lx;
          src(y, in.h, y0, y1, ly);
          src(x, in.w, x0, x1, lx);
          out.at(i, c, y, x) = float((1 - ly) * ((1 - lx) * in.at(i, c, y0, x0) + lx * in.at(i, c, y0, x1)) +
                                     ly * ((1 - lx) * in.at(i, c, y1, x0) + lx * in.at(i, c, y1, x1)));
        }
  return out;
}

Tensor concatCpu(const Tensor& a, const Tensor& b) {
  Tensor out(a.n, a.c + b.c, a.h, a.w);
  const size_t pa = size_t(a.c) * a.h * a.w, pb = size_t(b.c) * b.h * b.w;
  for (uint32_t i = 0; i < a.n; ++i) {
    std::copy_n(a.data.begin() + i * pa, pa, out.data.begin() + i * (pa + pb));
    std::copy_n(b.data.begin() + i * pb, pb, out.data.begin() + i * (pa + pb) + pa);
  }
  return out;
}

Tensor unetCpu(const UNetWeights& w, const Tensor& maps) {
  const auto& c = w.convs;
  // The seed's forward(): encoder0..3, then decoders on concatenations with the skips.
  Tensor x0 = convCpu(convCpu(maps, c[0]), c[1]);
  Tensor x1 = convCpu(convCpu(maxPoolCpu(x0), c[2]), c[3]);
  Tensor x2 = convCpu(convCpu(maxPoolCpu(x1), c[4]), c[5]);
  Tensor x3 = upsampleCpu(convCpu(convCpu(maxPoolCpu(x2), c[6]), c[7]));
  Tensor x4 = upsampleCpu(convCpu(convCpu(concatCpu(x3, x2), c[8]), c[9]));
  Tensor x5 = upsampleCpu(convCpu(convCpu(concatCpu(x4, x1), c[10]), c[11]));
  return convCpu(convCpu(convCpu(concatCpu(x5, x0), c[12]), c[13]), c[14]);
}

}  // namespace osr::nn
