// Environment maps: .exr and .hdr loading, bad files, the importance-sampling tables and the
// sampling functions (C++ twins, analytically; the GLSL twins are checked in
// tests/scene_gpu/test_scene_probe.cpp).
#include <ImfRgbaFile.h>
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>

#include "common/error.h"
#include "common/test_paths.h"
#include "scene/environment.h"
#include "scene/scene_test_util.h"
#include "scene/surface.h"

using namespace osr;

namespace {

// Files of this process only: the fixed names in gtest's shared TempDir() collided with
// the same suite run at the same time from another checkout or build folder.
std::string tempPrefix() {
  return osr::test::tempDir("scene_environment").string() + "/";
}

constexpr float kPi = 3.14159265358979f;


std::string temp(const std::string& name) {
  return tempPrefix() + name;
}

void expectInputError(const std::string& path, const std::string& part) {
  test::expectInputError([](const std::string& p) { scene::loadEnvironment(p); }, path, part);
}

}  // namespace

TEST(Environment, LoadsHdrAndExr) {
  scene::Environment ref = test::testEnvironment();
  std::vector<float> rgb;
  for (const auto& t : ref.texels) rgb.insert(rgb.end(), {t.r, t.g, t.b});
  std::string hdr = temp("env.hdr");
  ASSERT_TRUE(stbi_write_hdr(hdr.c_str(), 16, 8, 3, rgb.data()));
  std::string exr = temp("env.exr");
  {
    std::vector<Imf::Rgba> px;
    for (const auto& t : ref.texels) px.emplace_back(t.r, t.g, t.b, 1.0f);
    Imf::RgbaOutputFile out(exr.c_str(), 16, 8, Imf::WRITE_RGBA);
    out.setFrameBuffer(px.data(), 1, 16);
    out.writePixels(8);
  }
  for (const std::string& path : {hdr, exr}) {
    scene::Environment env = scene::loadEnvironment(path);
    ASSERT_EQ(env.width, 16u);
    ASSERT_EQ(env.height, 8u);
    // RGBE shares one exponent per texel (8-bit mantissas: ~1% of the largest channel), half
    // keeps ~0.1%. Row 0 stays the top row.
    for (size_t i = 0; i < env.texels.size(); ++i) {
      float largest = std::max({ref.texels[i].r, ref.texels[i].g, ref.texels[i].b});
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(env.texels[i][k], ref.texels[i][k], 0.01f * largest) << path << " texel " << i;
    }
  }
}

TEST(Environment, BadFiles) {
  expectInputError(temp("none.exr"), "not found");
  std::string junk = temp("junk.exr");
  std::FILE* f = std::fopen(junk.c_str(), "wb");
  std::fputs("this is not an image", f);
  std::fclose(f);
  expectInputError(junk, "OpenEXR");
  std::string junkHdr = temp("junk.hdr");
  std::rename(junk.c_str(), junkHdr.c_str());
  expectInputError(junkHdr, ".hdr");
  std::string png = test::dataPath("scene/checker.png");
  expectInputError(png, ".exr or .hdr");
  // A device was "file not found"; a pipe is refused before it is opened.
  expectInputError("/dev/zero", "not a regular file");
  expectInputError(test::makeFifo("scene_environment", "pipe.hdr"), "not a regular file");
}

// stb_image's .hdr decoder loops forever on a run-length scanline with a run of length 0, or
// one cut short by the end of the file (common/hdr_check.h): both are refused before it runs.
TEST(Environment, HdrThatStbImageWouldNeverFinishIsRefused) {
  std::vector<float> rgb(16 * 8 * 3, 0.5f);
  std::string good = temp("rle.hdr");
  ASSERT_TRUE(stbi_write_hdr(good.c_str(), 16, 8, 3, rgb.data()));  // run-length encoded
  std::vector<char> bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string text(bytes.begin(), bytes.end());
  const size_t firstScanline = text.find("+X 16\n") + 6;
  ASSERT_EQ(bytes.at(firstScanline), 2);
  auto write = [&](const std::string& name, std::vector<char> b) {
    std::string path = temp(name);
    std::ofstream(path, std::ios::binary).write(b.data(), std::streamsize(b.size()));
    return path;
  };
  std::vector<char> zeroRun = bytes;
  zeroRun.at(firstScanline + 4) = 0;  // the first count of the first channel
  expectInputError(write("zero_run.hdr", zeroRun), "run of length 0 in scanline 0");
  std::vector<char> cut(bytes.begin(), bytes.begin() + long(firstScanline) + 40);
  expectInputError(write("cut.hdr", cut), "truncated Radiance .hdr");
  // Cut at a scanline's start, stb_image reads the rest as black pixels: loaded, not refused.
  std::vector<char> atScanline(bytes.begin(), bytes.begin() + long(firstScanline));
  EXPECT_EQ(scene::loadEnvironment(write("black.hdr", atScanline)).width, 16u);
  EXPECT_EQ(scene::loadEnvironment(good).height, 8u);
  // stb_image reads header lines as C strings: one that starts with a NUL ends the header.
  std::string nulLine = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n";
  nulLine += std::string("\0junk\n", 6) + "-Y 8 +X 16\n" + std::string("\x02\x02\x00\x10\x00", 5);
  expectInputError(write("nul_line.hdr", {nulLine.begin(), nulLine.end()}), "run of length 0");
  // A header claiming 5555555 x 8 pixels, read pixel by pixel (over 10 s under ASan).
  const std::string wide = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 5555555\n";
  expectInputError(write("wide.hdr", {wide.begin(), wide.end()}), "5555555 x 8 pixels, more than osr-vk reads");
}

TEST(Environment, CdfTables) {
  scene::Environment env = test::testEnvironment();
  std::vector<float> cdf = scene::environmentCdf(env);
  ASSERT_EQ(cdf.size(), 8u + 16u * 8u);
  EXPECT_EQ(cdf[7], 1.0f);
  for (uint32_t y = 0; y < 8; ++y) {
    EXPECT_EQ(cdf[8 + y * 16 + 15], 1.0f);
    for (uint32_t x = 1; x < 16; ++x) EXPECT_GE(cdf[8 + y * 16 + x], cdf[8 + y * 16 + x - 1]);
  }
  // A black map samples uniformly over the sphere instead of dividing by zero.
  scene::Environment black = env;
  for (auto& t : black.texels) t = glm::vec4(0.0f);
  std::vector<float> u = scene::environmentCdf(black);
  EXPECT_NEAR(u[8 + 3], 4.0f / 16.0f, 1e-6f);
  EXPECT_EQ(u[7], 1.0f);
}

TEST(Environment, SamplingIsConsistentAndUnbiased) {
  scene::Environment env = test::testEnvironment();
  std::vector<float> cdf = scene::environmentCdf(env);
  // Integral of luminance over the sphere, texel by texel (exact for piecewise constant).
  double exact = 0.0;
  for (uint32_t y = 0; y < 8; ++y) {
    double solidAngle = (2.0 * kPi / 16) * (std::cos(y * kPi / 8) - std::cos((y + 1) * kPi / 8));
    for (uint32_t x = 0; x < 16; ++x)
      exact += scene::luminance(glm::vec3(env.texels[y * 16 + x])) * solidAngle;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  double estimate = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    float pdf;
    glm::vec3 radiance;
    glm::vec3 dir = scene::sampleEnvironment(env, cdf, {u01(rng), u01(rng)}, pdf, radiance);
    ASSERT_NEAR(glm::length(dir), 1.0f, 1e-5f);
    ASSERT_GT(pdf, 0.0f);
    if (i % 100 == 0) {
      EXPECT_NEAR(scene::environmentPdf(env, cdf, dir), pdf, 2e-3f * pdf) << i;
      EXPECT_EQ(scene::environmentRadiance(env, dir), radiance) << i;
    }
    estimate += scene::luminance(radiance) / pdf;
  }
  estimate /= n;
  // Importance sampling ~ luminance: the estimator's variance is small; 1% is many sigmas.
  EXPECT_NEAR(estimate, exact, 0.01 * exact);
  // The pdf integrates to one over the sphere (uniform directions, MC).
  double integral = 0.0;
  for (int i = 0; i < n; ++i) {
    float z = 1.0f - 2.0f * u01(rng), phi = 2.0f * kPi * u01(rng),
          r = std::sqrt(std::max(0.0f, 1 - z * z));
    integral +=
        scene::environmentPdf(env, cdf, {r * std::cos(phi), z, r * std::sin(phi)}) * 4.0f * kPi;
  }
  EXPECT_NEAR(integral / n, 1.0, 0.03);
}

TEST(Environment, DirectionMappingRoundTripsAndMatchesBlender) {
  for (glm::vec2 uv : {glm::vec2(0.1f, 0.2f), glm::vec2(0.5f, 0.5f), glm::vec2(0.9f, 0.7f)}) {
    glm::vec2 back = scene::environmentUv(scene::environmentDirection(uv));
    EXPECT_NEAR(back.x, uv.x, 1e-5f);
    EXPECT_NEAR(back.y, uv.y, 1e-5f);
  }
  // Image centre looks along +X (Blender's), the top row is +Y (up), u = 0.75 is +Z.
  glm::vec3 c = scene::environmentDirection({0.5f, 0.5f});
  EXPECT_NEAR(c.x, 1.0f, 1e-6f);
  EXPECT_NEAR(scene::environmentDirection({0.3f, 0.0f}).y, 1.0f, 1e-6f);
  EXPECT_NEAR(scene::environmentDirection({0.75f, 0.5f}).z, 1.0f, 1e-6f);
}


// The neutral sky (scene::neutralEnvironment) is white, kNeutralSkyNadir straight down and
// about kNeutralSkyZenith straight up, and brightest towards the key, in
// front-left above the default camera: a box's front (+Z) face sees more of it than its right
// (+X) face, which is what makes the faces differ.
TEST(Environment, NeutralSkyIsWhiteWithAKeyLight) {
  const scene::Environment env = scene::neutralEnvironment();
  ASSERT_EQ(env.texels.size(), size_t(env.width) * env.height);
  EXPECT_EQ(env.path, "");
  auto at = [&](uint32_t x, uint32_t y) { return env.texels[size_t(y) * env.width + x]; };
  for (const glm::vec4& t : env.texels) {
    EXPECT_EQ(t.r, t.g);
    EXPECT_EQ(t.g, t.b);
  }
  // Straight up the key (37 degrees away, cos^16 = 0.03) adds a little to the sky.
  EXPECT_GT(at(0, 0).r, scene::kNeutralSkyZenith - 0.01f);
  EXPECT_LT(at(0, 0).r, scene::kNeutralSkyZenith + 0.2f);
  EXPECT_NEAR(at(0, env.height - 1).r, scene::kNeutralSkyNadir, 0.01f);
  size_t brightest = 0;
  for (size_t i = 0; i < env.texels.size(); ++i)
    if (env.texels[i].r > env.texels[brightest].r) brightest = i;
  const float pi = 3.14159265f;
  const float phi = ((float(brightest % env.width) + 0.5f) / float(env.width) - 0.5f) * 2.f * pi;
  const float theta = (float(brightest / env.width) + 0.5f) / float(env.height) * pi;
  const glm::vec3 dir(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  EXPECT_GT(dir.y, 0.5f) << "above";
  EXPECT_GT(dir.z, 0.3f) << "in front (+Z)";
  EXPECT_LT(dir.x, 0.f) << "to the left (-X)";
  EXPECT_GT(env.texels[brightest].r, scene::kNeutralSkyKey);
}
