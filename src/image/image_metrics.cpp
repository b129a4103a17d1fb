#include "image/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace osr::image {

namespace {

double toneMap(float x) {
  double v = std::isfinite(x) ? std::max(0.f, x) : 0.0;
  v = v / (1.0 + v);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

// SSIM of one channel plane (w x h), Gaussian window applied separably.
double ssimPlane(const std::vector<double>& x, const std::vector<double>& y, int w, int h) {
  constexpr int kRadius = 5;
  constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  double kernel[2 * kRadius + 1];
  double ksum = 0.0;
  for (int i = -kRadius; i <= kRadius; ++i)
    ksum += kernel[i + kRadius] = std::exp(-i * i / (2 * kSigma * kSigma));
  for (double& k : kernel) k /= ksum;
  // Blur with clamp-to-edge borders.
  auto blur = [&](const std::vector<double>& in) {
    std::vector<double> tmp(in.size()), out(in.size());
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        double s = 0.0;
        for (int i = -kRadius; i <= kRadius; ++i)
          s += kernel[i + kRadius] * in[size_t(r) * w + std::clamp(c + i, 0, w - 1)];
        tmp[size_t(r) * w + c] = s;
      }
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        double s = 0.0;
        for (int i = -kRadius; i <= kRadius; ++i)
          s += kernel[i + kRadius] * tmp[size_t(std::clamp(r + i, 0, h - 1)) * w + c];
        out[size_t(r) * w + c] = s;
      }
    return out;
  };
  std::vector<double> xx(x.size()), yy(x.size()), xy(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  auto mx = blur(x), my = blur(y), sxx = blur(xx), syy = blur(yy), sxy = blur(xy);
  double sum = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    double vx = sxx[i] - mx[i] * mx[i], vy = syy[i] - my[i] * my[i], cxy = sxy[i] - mx[i] * my[i];
    sum += ((2 * mx[i] * my[i] + kC1) * (2 * cxy + kC2)) /
           ((mx[i] * mx[i] + my[i] * my[i] + kC1) * (vx + vy + kC2));
  }
  return sum / double(x.size());
}

}  // namespace

double relMse(const RgbImage& a, const RgbImage& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    double d = double(a.rgb[i]) - b.rgb[i];
    sum += d * d / (double(b.rgb[i]) * b.rgb[i] + kRelMseEpsilon);
  }
  return sum / double(a.rgb.size());
}

double referenceNoise(const RgbImage& reference, const RgbImage& luminanceVariance) {
  if (reference.width != luminanceVariance.width || reference.height != luminanceVariance.height)
    throw std::invalid_argument("referenceNoise: the variance is not the reference's size");
  // Each channel's variance, the luminance's in proportion to the channel's share.
  RgbImage channelVariance = luminanceVariance;
  for (size_t i = 0; i < reference.rgb.size() / 3; ++i) {
    const double y = reference.luminance(i);
    for (int c = 0; c < 3; ++c) {
      const double share = y > 1e-8 ? reference.rgb[3 * i + c] / y : 1.0;
      channelVariance.rgb[3 * i + c] = float(double(luminanceVariance.rgb[3 * i]) * share * share);
    }
  }
  return referenceChannelNoise(reference, channelVariance);
}

double referenceChannelNoise(const RgbImage& reference, const RgbImage& channelVariance) {
  if (reference.width != channelVariance.width || reference.height != channelVariance.height)
    throw std::invalid_argument("referenceChannelNoise: the variance is not the reference's size");
  double sum = 0.0;
  for (size_t i = 0; i < reference.rgb.size(); ++i) {
    const double r = reference.rgb[i];
    sum += double(channelVariance.rgb[i]) / (r * r + kRelMseEpsilon);
  }
  return sum / double(reference.rgb.size());
}

double meanLuminance(const RgbImage& image) {
  double sum = 0.0;
  for (size_t i = 0; i < image.rgb.size() / 3; ++i) sum += image.luminance(i);
  return sum / double(image.rgb.size() / 3);
}

RgbImage downsample(const RgbImage& image, int factor) {
  if (factor < 1 || image.width % factor || image.height % factor)
    throw std::invalid_argument("downsample: size not divisible by the factor");
  RgbImage out;
  out.width = image.width / factor;
  out.height = image.height / factor;
  out.rgb.assign(size_t(out.width) * out.height * 3, 0.f);
  const float norm = 1.f / float(factor * factor);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c)
        out.rgb[(size_t(y / factor) * out.width + x / factor) * 3 + c] +=
            image.rgb[(size_t(y) * image.width + x) * 3 + c] * norm;
  return out;
}

ImageMetrics compareImages(const RgbImage& a, const RgbImage& b) {
  ImageMetrics m;
  m.relmse = relMse(a, b);
  const int w = a.width, h = a.height;
  double se = 0.0, ssim = 0.0;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> x(size_t(w) * h), y(size_t(w) * h);
    for (size_t i = 0; i < x.size(); ++i) {
      x[i] = toneMap(a.rgb[i * 3 + c]);
      y[i] = toneMap(b.rgb[i * 3 + c]);
      se += (x[i] - y[i]) * (x[i] - y[i]);
    }
    ssim += ssimPlane(x, y, w, h) / 3.0;
  }
  double mse = se / double(a.rgb.size());
  m.psnr = mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
  m.ssim = ssim;
  double lb = meanLuminance(b);
  m.lumRatio = lb != 0.0 ? meanLuminance(a) / lb : std::numeric_limits<double>::quiet_NaN();
  return m;
}

}  // namespace osr::image
