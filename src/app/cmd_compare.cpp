// osr-vk compare TEST REF: one JSON line with relmse, psnr, ssim and lum_ratio (TEST over REF);
// see image/image_metrics.h for the definitions. Exit 2 on unreadable files or different sizes.
#include <cmath>
#include <cstdio>

#include "app/args.h"
#include "app/commands.h"
#include "image/image_metrics.h"
#include "common/error.h"

namespace osr::app {

int runCompare(const std::vector<std::string>& args) {
  Args a(args, "compare");
  auto files = a.positional();
  a.finish();
  if (files.size() != 2) throw InputError("compare: expected two images, TEST.exr REF.exr (the reference second)");
  image::RgbImage x = image::readExrRgb(files[0]);
  image::RgbImage y = image::readExrRgb(files[1]);
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
      "\"relmse_epsilon\": %g, \"tonemap\": \"%s\"}\n",
      num(m.relmse).c_str(), num(m.psnr).c_str(), num(m.ssim).c_str(), num(m.lumRatio).c_str(),
      image::kRelMseEpsilon, image::kToneMapDescription);
  return 0;
}

}  // namespace osr::app
