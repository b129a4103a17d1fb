// Image comparison metrics of `osr-vk compare` and the reference tests.
//   relmse    mean over pixels and RGB of (a - b)^2 / (b^2 + 0.01)       (on linear radiance)
//   psnr, ssim on the tone-mapped images t(x) = sRGB_OETF(x / (1 + x)) per channel, in [0, 1]
//             (SSIM: Wang et al. 2004, 11x11 Gaussian window sigma 1.5, C1 = 0.01^2,
//             C2 = 0.03^2, mean over pixels and RGB)
//   lumRatio  mean Rec.709 luminance of a over that of b
#pragma once
#include "image/image_io.h"

namespace osr::image {

inline constexpr double kRelMseEpsilon = 0.01;
inline constexpr const char* kToneMapDescription = "srgb(x/(1+x))";

struct ImageMetrics {
  double relmse = 0.0;
  double psnr = 0.0;
  double ssim = 0.0;
  double lumRatio = 0.0;
};

// a and b have the same size (the caller checks).
ImageMetrics compareImages(const RgbImage& a, const RgbImage& b);
double relMse(const RgbImage& a, const RgbImage& b);
double meanLuminance(const RgbImage& image);
// What a reference's own noise adds to any image's relMSE against it: the mean over pixels and
// RGB of var_c / (r_c^2 + 0.01), each channel's variance the variance of the pixel's luminance
// estimate (osr-vk's `variance` layer, grey) times (r_c / Y)^2. An image's relMSE less this
// estimates its relMSE against the converged image.
double referenceNoise(const RgbImage& reference, const RgbImage& luminanceVariance);
// The same from each channel's variance of the reference's mean (the `spread` layer of
// tools/merge_references.py, from the spread of independent renders): the mean over pixels and
// RGB of var_c / (r_c^2 + 0.01), with no assumption on how the channels' noise is correlated.
double referenceChannelNoise(const RgbImage& reference, const RgbImage& channelVariance);
// Box-filters by an integer factor (width and height divisible by it).
RgbImage downsample(const RgbImage& image, int factor);

}  // namespace osr::image
