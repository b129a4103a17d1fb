// OpenEXR/PNG writers and the EXR reader: layers round-trip (float exactly, half within half
// precision), the reference EXRs read, failures leave an existing file untouched, a vast or
// empty data window is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
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
  const std::string cornell = test::referencePath("cornell/cornell_cycles_4096spp.exr");
  EXPECT_TRUE(image::exrChannels(cornell).count("R"));
  EXPECT_FALSE(image::exrChannels(cornell).count("variance.Y"));  // Cycles writes no variance
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

// A header's data window is the file's word: patched to a vast or an inverted window, a small
// file is refused by its header before OpenEXR opens it (the reader allocated all of a vast
// window's pixels: 30 s and 2.4 GB for an 878-byte file claiming 16777216 x 8).
TEST(ImageIo, ReadingRefusesAVastOrEmptyDataWindow) {
  fs::path d = tempDir();
  const std::string good = (d / "good.exr").string();
  image::writeExr(good, testImage(4, 2), image::ExrPixelType::Half);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // "dataWindow\0box2i\0", the size (16), then xMin, yMin, xMax, yMax.
  const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  auto patched = [&](const char* name, int32_t xMax, int32_t yMax) {
    std::string b = bytes;
    std::memcpy(&b[at + key.size() + 4 + 8], &xMax, 4);
    std::memcpy(&b[at + key.size() + 4 + 12], &yMax, 4);
    const std::string path = (d / name).string();
    std::ofstream(path, std::ios::binary) << b;
    return path;
  };
  auto message = [](const std::string& path) {
    try {
      image::readExrRgb(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  const std::string vast = patched("vast.exr", (1 << 24) - 1, 1);  // as many lines as before
  EXPECT_EQ(message(vast), vast + ": 16777216 x 2 pixels, more than osr-vk reads (65536 a side, 268435456 in all)");
  const std::string empty = patched("empty.exr", -5, 1);
  EXPECT_EQ(message(empty), empty + ": empty OpenEXR data window");
  EXPECT_EQ(image::readExrRgb(good).width, 4);
  fs::remove_all(d);
}

TEST(ImageIo, PngAutoExposureMapsTheMeteredMeanToTheKey) {
  image::RgbImage img{4, 2, std::vector<float>(24, 0.045f)};
  EXPECT_NEAR(image::autoExposureEv(img), std::log2(image::kExposureKey / 0.045), 1e-6);
  fs::path d = tempDir();
  std::string path = (d / "p.png").string();
  image::writePng(path, img, std::nullopt);
  std::ifstream f(path, std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  fs::remove_all(d);
}

namespace {
// A grey object (a 12 x 12 square of luminance `grey`, with a 2 x 2 light of 50 on it) in
// the middle of a 128 x 128 black image: 1% of the pixels.
image::RgbImage objectOnBlack(float grey) {
  image::RgbImage img{128, 128, std::vector<float>(128 * 128 * 3, 0.f)};
  for (int y = 58; y < 70; ++y)
    for (int x = 58; x < 70; ++x)
      for (int c = 0; c < 3; ++c) img.rgb[(size_t(y) * 128 + x) * 3 + c] = grey;
  for (int y = 60; y < 62; ++y)
    for (int x = 60; x < 62; ++x)
      for (int c = 0; c < 3; ++c) img.rgb[(size_t(y) * 128 + x) * 3 + c] = 50.f;
  return img;
}
}  // namespace

// A small object on black is exposed for the object: its grey lands within a stop of the key
// (0.18), neither white (the old log-average over every pixel gave it +10 EV: 1e-4 floors
// dominate) nor darkened by the light on it.
TEST(ImageIo, AutoExposureOfASmallObjectOnBlack) {
  for (float grey : {0.02f, 0.3f, 4.f}) {
    const image::RgbImage img = objectOnBlack(grey);
    const double exposed = grey * std::exp2(image::autoExposureEv(img));
    EXPECT_GT(exposed, image::kExposureKey / 2) << "grey " << grey;
    EXPECT_LT(exposed, image::kExposureKey * 2) << "grey " << grey;
  }
}

// A 1-spp render: most pixels that see a surface are 0, the others a few times too bright
// (here 1 in 4 pixels at 4x, unbiased). Metered with the depth layer (which says the zeros
// saw a surface), it gets the converged image's exposure within a tenth of a stop.
TEST(ImageIo, AutoExposureOfAOneSampleRender) {
  const int w = 64, h = 64;
  image::RgbImage converged{w, h, std::vector<float>(size_t(w) * h * 3, 0.f)}, noisy = converged;
  std::vector<float> depth(size_t(w) * h, 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 16; x < 48; ++x) {  // an object over the middle half, black elsewhere
      const size_t i = size_t(y) * w + x;
      const float v = 0.05f + 0.4f * float(y) / float(h);
      depth[i] = 3.f;
      for (int c = 0; c < 3; ++c) {
        converged.rgb[i * 3 + c] = v;
        noisy.rgb[i * 3 + c] = (x + 2 * y) % 4 == 0 ? 4.f * v : 0.f;
      }
    }
  const double evConverged = image::autoExposureEv(converged, depth);
  EXPECT_NEAR(image::autoExposureEv(noisy, depth), evConverged, 0.1);
  EXPECT_NEAR(image::autoExposureEv(converged), evConverged, 1e-9) << "black is never metered";
  // Without the depth layer only the lit quarter counts: two stops darker, not blown out.
  EXPECT_NEAR(image::autoExposureEv(noisy), evConverged - 2.0, 0.1);
}

TEST(ImageIo, AutoExposureOfNothingIsZero) {
  image::RgbImage black{8, 8, std::vector<float>(8 * 8 * 3, 0.f)};
  EXPECT_EQ(image::autoExposureEv(black), 0.0);
  EXPECT_EQ(image::autoExposureEv(black, std::vector<float>(64, 1.f)), 0.0);
}
