// OpenEXR/PNG writers and the EXR reader: layers round-trip (float exactly, half within half
// precision), the reference EXRs read, failures leave an existing file untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "image/image_io.h"
#include "common/error.h"
#include "common/test_paths.h"

using namespace osr;
namespace fs = std::filesystem;

namespace {
fs::path tempDir() { return test::tempDir("image_io"); }

image::LayeredImage testImage(int w, int h) {
  image::LayeredImage img{w, h, {}};
  image::ImageLayer rgb{"", {"R", "G", "B"}, {}}, depth{"depth", {"Z"}, {}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      rgb.data.insert(rgb.data.end(), {x * 0.25f, y * 1.5f, 1000.f + x});
      depth.data.push_back(float(y * w + x));
    }
  img.layers = {rgb, depth};
  return img;
}
}  // namespace

TEST(ImageIo, ExrRoundTripsFloatAndHalf) {
  fs::path d = tempDir();
  image::LayeredImage img = testImage(7, 5);  // odd sizes
  for (auto type : {image::ExrPixelType::Float, image::ExrPixelType::Half}) {
    std::string path = (d / "rt.exr").string();
    image::writeExr(path, img, type);
    image::RgbImage back = image::readExrRgb(path);
    ASSERT_EQ(back.width, 7);
    ASSERT_EQ(back.height, 5);
    for (size_t i = 0; i < back.rgb.size(); ++i) {
      float want = img.layers[0].data[i];
      float tol = type == image::ExrPixelType::Float ? 0.f : std::abs(want) * 1e-3f;
      ASSERT_NEAR(back.rgb[i], want, tol) << i;
    }
  }
  // No temporary left behind.
  for (auto& e : fs::directory_iterator(d))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  fs::remove_all(d);
}

TEST(ImageIo, ReadsTheCyclesReferences) {
  image::RgbImage img = image::readExrRgb(test::referencePath("cornell/cornell_cycles_4096spp.exr"));
  EXPECT_EQ(img.width, 256);
  EXPECT_EQ(img.height, 256);
  double sum = 0;
  for (float v : img.rgb) {
    ASSERT_TRUE(std::isfinite(v));
    sum += v;
  }
  EXPECT_GT(sum, 0.0);
}

TEST(ImageIo, FailuresAreInputErrorsAndKeepExistingFiles) {
  fs::path d = tempDir();
  std::string existing = (d / "keep.exr").string();
  { std::ofstream(existing) << "precious"; }
  EXPECT_THROW(image::readExrRgb(existing), InputError);  // not an EXR
  EXPECT_THROW(image::readExrRgb((d / "missing.exr").string()), InputError);
  EXPECT_THROW(
      image::writeExr((d / "no_dir" / "x.exr").string(), testImage(2, 2), image::ExrPixelType::Half),
      InputError);
  EXPECT_THROW(image::checkWritable((d / "no_dir" / "x.exr").string()), InputError);
  EXPECT_THROW(image::checkWritable(d.string()), InputError);
  image::checkWritable(existing);
  std::ifstream in(existing);
  std::string content;
  in >> content;
  EXPECT_EQ(content, "precious");
  fs::remove_all(d);
}

TEST(ImageIo, PngAutoExposureMapsLogAverageToMiddleGrey) {
  image::RgbImage img{4, 2, std::vector<float>(24, 0.045f)};
  EXPECT_NEAR(image::autoExposureEv(img), std::log2(0.18 / (0.045 + 1e-4)), 1e-6);
  fs::path d = tempDir();
  std::string path = (d / "p.png").string();
  image::writePng(path, img, std::nullopt);
  std::ifstream f(path, std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  fs::remove_all(d);
}
