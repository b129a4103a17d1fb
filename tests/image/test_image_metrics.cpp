// compare's metrics against values computed by hand on constant and simple images.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "image/image_metrics.h"

using namespace osr;

namespace {
image::RgbImage constant(int w, int h, float v) {
  return {w, h, std::vector<float>(size_t(w) * h * 3, v)};
}
double toneMapped(double x) {
  x = x / (1 + x);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055;
}
}  // namespace

TEST(ImageMetrics, IdenticalImages) {
  image::RgbImage a = constant(13, 9, 0.5f);
  a.rgb[4] = 3.f;
  auto m = image::compareImages(a, a);
  EXPECT_EQ(m.relmse, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr));
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);
  EXPECT_NEAR(m.lumRatio, 1.0, 1e-12);
}

TEST(ImageMetrics, ReferenceNoiseIsWhatTheReferencesNoiseAddsToRelMse) {
  // Grey: every channel's variance is the luminance's.
  const image::RgbImage ref = constant(8, 8, 0.5f), var = constant(8, 8, 0.002f);
  EXPECT_NEAR(image::referenceNoise(ref, var), 0.002 / (0.25 + 0.01), 1e-9);
  // Coloured: each channel's variance is the luminance's times (c / Y)^2.
  image::RgbImage red = constant(4, 4, 0.f);
  for (size_t i = 0; i < red.rgb.size(); i += 3) red.rgb[i] = 0.6f, red.rgb[i + 1] = 0.3f, red.rgb[i + 2] = 0.1f;
  const double y = 0.2126 * 0.6 + 0.7152 * 0.3 + 0.0722 * 0.1;
  double want = 0.0;
  for (double c : {0.6, 0.3, 0.1}) want += 0.002 * (c / y) * (c / y) / (c * c + 0.01) / 3.0;
  EXPECT_NEAR(image::referenceNoise(red, constant(4, 4, 0.002f)), want, 1e-6 * want);
  EXPECT_THROW(image::referenceNoise(red, var), std::invalid_argument);
  // Over many noisy references of one truth, the mean relMSE of the truth against them is
  // that figure (up to 2.35 sigma^2 from the noise in the denominator: 0.1 % here).
  image::RgbImage truth = constant(64, 64, 1.0f), noisy = truth;
  uint32_t state = 1;
  double sum = 0.0, noise = 0.0;
  const float sigma = 0.02f;
  for (int k = 0; k < 20; ++k) {
    for (size_t i = 0; i < noisy.rgb.size(); i += 3) {
      state = state * 1664525u + 1013904223u;
      const float v = 1.0f + sigma * ((state >> 8) * (1.f / 16777216.f) * 2.f - 1.f) * std::sqrt(3.f);
      noisy.rgb[i] = noisy.rgb[i + 1] = noisy.rgb[i + 2] = v;
    }
    sum += image::relMse(truth, noisy);
    noise += image::referenceNoise(noisy, constant(64, 64, sigma * sigma));
  }
  EXPECT_NEAR(sum / noise, 1.0, 0.01);
}

TEST(ImageMetrics, ReferenceChannelNoiseTakesEachChannelsOwn) {
  // Channels of different noise, uncorrelated: what referenceNoise's grey assumption cannot
  // say. Over many noisy references of one truth, the truth's mean relMSE against them is the
  // figure from each channel's variance.
  const float sigma[3] = {0.02f, 0.01f, 0.04f};
  const image::RgbImage truth = constant(64, 64, 1.0f);
  image::RgbImage noisy = truth, variance = truth;
  for (size_t i = 0; i < variance.rgb.size(); ++i) variance.rgb[i] = sigma[i % 3] * sigma[i % 3];
  uint32_t state = 7;
  double sum = 0.0, noise = 0.0;
  for (int k = 0; k < 20; ++k) {
    for (size_t i = 0; i < noisy.rgb.size(); ++i) {
      state = state * 1664525u + 1013904223u;
      noisy.rgb[i] = 1.0f + sigma[i % 3] * ((state >> 8) * (1.f / 16777216.f) * 2.f - 1.f) * std::sqrt(3.f);
    }
    sum += image::relMse(truth, noisy);
    noise += image::referenceChannelNoise(noisy, variance);
  }
  EXPECT_NEAR(sum / noise, 1.0, 0.01);
  EXPECT_NEAR(image::referenceChannelNoise(truth, variance), (0.0004 + 0.0001 + 0.0016) / 3.0 / 1.01, 1e-9);
  EXPECT_THROW(image::referenceChannelNoise(truth, constant(4, 4, 0.f)), std::invalid_argument);
}

TEST(ImageMetrics, ConstantImagesMatchClosedForms) {
  image::RgbImage a = constant(16, 12, 1.0f), b = constant(16, 12, 0.5f);
  auto m = image::compareImages(a, b);
  EXPECT_NEAR(m.relmse, 0.25 / (0.25 + 0.01), 1e-9);
  EXPECT_NEAR(m.lumRatio, 2.0, 1e-9);
  double d = toneMapped(1.0) - toneMapped(0.5);
  EXPECT_NEAR(m.psnr, 10 * std::log10(1 / (d * d)), 1e-6);
  // Constant images: SSIM reduces to its luminance term.
  double x = toneMapped(1.0), y = toneMapped(0.5), c1 = 1e-4;
  EXPECT_NEAR(m.ssim, (2 * x * y + c1) / (x * x + y * y + c1), 1e-9);
}

TEST(ImageMetrics, DownsampleAveragesBlocks) {
  image::RgbImage a{4, 2, {}};
  for (int i = 0; i < 24; ++i) a.rgb.push_back(float(i));
  image::RgbImage d = image::downsample(a, 2);
  ASSERT_EQ(d.width, 2);
  ASSERT_EQ(d.height, 1);
  // Block (0,0): pixels 0, 1, 4, 5 -> R values 0, 3, 12, 15.
  EXPECT_FLOAT_EQ(d.rgb[0], 7.5f);
  EXPECT_NEAR(image::meanLuminance(a), image::meanLuminance(d), 1e-5);
}
