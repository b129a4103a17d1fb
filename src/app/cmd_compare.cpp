// osr-vk compare TEST REF: one JSON line with relmse, psnr, ssim and lum_ratio (TEST over REF);
// see image/image_metrics.h for the definitions. A TEST an integer multiple of REF's size is
// box-filtered down to it (the viewer renders at the window's size, references are smaller).
// Exit 2 on unreadable files or sizes that are not such multiples.
#include <cmath>
#include <cstdio>
#include <string>

#include "app/args.h"
#include "app/commands.h"
#include "common/error.h"
#include "image/image_metrics.h"

namespace osr::app {

int runCompare(const std::vector<std::string>& args) {
  Args a(args, "compare");
  auto files = a.positional();
  a.finish();
  if (files.size() != 2)
    throw InputError("compare: expected two images, TEST.exr REF.exr (the reference second)");
  image::RgbImage x = image::readExrRgb(files[0]);
  image::RgbImage y = image::readExrRgb(files[1]);
  int factor = 1;
  if (y.width > 0 && y.height > 0 && x.width % y.width == 0 && x.height % y.height == 0 &&
      x.width / y.width == x.height / y.height)
    factor = x.width / y.width;
  if (factor > 1) x = image::downsample(x, factor);
  if (x.width != y.width || x.height != y.height)
    throw InputError(files[0] + ": size " + std::to_string(x.width) + "x" +
                     std::to_string(x.height) + " differs from " + files[1] + " (" +
                     std::to_string(y.width) + "x" + std::to_string(y.height) + ")");
  image::ImageMetrics m = image::compareImages(x, y);
  auto num = [](double v) {
    char buf[64];
    if (!std::isfinite(v)) return std::string("null");  // identical images: psnr = inf
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return std::string(buf);
  };
  std::printf(
      "{\"relmse\": %s, \"psnr\": %s, \"ssim\": %s, \"lum_ratio\": %s, "
      "\"relmse_epsilon\": %g, \"tonemap\": \"%s\"%s}\n",
      num(m.relmse).c_str(), num(m.psnr).c_str(), num(m.ssim).c_str(), num(m.lumRatio).c_str(),
      image::kRelMseEpsilon, image::kToneMapDescription,
      factor > 1 ? (", \"test_downsampled_by\": " + std::to_string(factor)).c_str() : "");
  return 0;
}

}  // namespace osr::app
