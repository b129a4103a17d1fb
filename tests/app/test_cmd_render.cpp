// `osr-vk [options] scene.gltf` as a user runs it: the layers of the EXR, --quiet, --time, and
// bad input (unknown flags, negative spp, unwritable output, unreadable environment map, bad
// mode): one stderr line, exit 2, and an existing output file left untouched.
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <tuple>

#include "app/cli_runner.h"
#include "image/image_io.h"
#include "common/vk_test.h"
#include "pt/gltf_writer.h"
#include "scene/scene.h"

using namespace osr;
namespace fs = std::filesystem;

namespace {
using Result = test::CliResult;
Result run(const std::string& args) {
  return test::runOsrVk(args);
}
std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
fs::path tempDir() { return test::tempDir("cmd_render"); }
const std::string kCornell = test::referencePath("cornell/cornell.gltf");
}  // namespace

TEST(CmdRender, PreviewWritesAllLayersQuietly) {
  fs::path d = tempDir();
  std::string exr = (d / "out.exr").string(), png = (d / "out.png").string();
  Result r = run("--mode preview --width 8 --height 6 --spp 1 --quiet --offline " + exr +
                 " --png " + png + " " + kCornell);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out, "");
  Imf::InputFile f(exr.c_str());
  const Imf::ChannelList& ch = f.header().channels();
  for (const char* name :
       {"R", "G", "B", "direct.R", "indirect.B", "albedo.G", "normal.X", "normal.Z", "depth.Z"})
    EXPECT_NE(ch.findChannel(name), nullptr) << name;
  image::RgbImage img = image::readExrRgb(exr);
  EXPECT_EQ(img.width, 8);
  EXPECT_EQ(img.height, 6);
  EXPECT_EQ(slurp(png).substr(1, 3), "PNG");
  fs::remove_all(d);
}

// Without --mode: path tracing, denoised (at 2 spp by the a-trous filter: the network takes
// over from kNetworkMinSamples); the EXR keeps the raw colour as its 'noisy' layer.
TEST(CmdRender, DefaultIsPathTracingWithTheFilter) {
  fs::path d = tempDir();
  std::string exr = (d / "default.exr").string();
  Result r = run("--spp 2 --width 32 --offline " + exr + " " + kCornell);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("2 spp in"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("denoise (atrous)"), std::string::npos) << r.out;
  Imf::InputFile f(exr.c_str());
  EXPECT_NE(f.header().channels().findChannel("noisy.R"), nullptr);
  // The share of light seen directly, which the denoisers keep out (training data reads it).
  EXPECT_NE(f.header().channels().findChannel("light.Y"), nullptr);
  fs::remove_all(d);
}

TEST(CmdRender, SizeFollowsTheCameraAspectAndCamerasAreSelectable) {
  fs::path d = tempDir();
  std::string exr = (d / "c.exr").string();
  // cornell's camera has aspect 1: --height alone gives a square image.
  for (auto [args, w, h] :
       {std::tuple{"--height 6 --camera Camera", 6, 6}, std::tuple{"--width 10 --camera 0", 10, 10},
        std::tuple{"--width 12 --height 4", 12, 4}}) {
    Result r = run(std::string("--mode preview --spp 1 --quiet ") + args + " --offline " + exr +
                   " " + kCornell);
    ASSERT_EQ(r.code, 0) << args << ": " << r.out;
    image::RgbImage img = image::readExrRgb(exr);
    EXPECT_EQ(img.width, w) << args;
    EXPECT_EQ(img.height, h) << args;
  }
  fs::remove_all(d);
}

// Checked on osr-vk's own clock, which it prints: the command's wall time, start-up with cold
// shader caches included, took 44 s on 2 cores at load 8 (docs/testing.md "Tests that time").
TEST(CmdRender, TimeLimitStopsTheRenderWithProgress) {
  fs::path d = tempDir();
  std::string exr = (d / "t.exr").string();
  Result r = run("--mode path --width 16 --spp 1000000 --time 1 --offline " + exr + " " + kCornell);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto loop = test::renderLoopNote(r.out);
  ASSERT_TRUE(loop) << r.out;
  // A million samples per pixel would take minutes: the loop stops within a second of the
  // budget less what it holds back (the first submission always runs).
  EXPECT_LT(loop->to, std::max(1.0 - loop->held, loop->from) + 1.0) << r.out;
  EXPECT_NE(r.out.find("spp"), std::string::npos) << r.out;  // progress line
  EXPECT_NE(r.out.find("remaining"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(exr));
  fs::remove_all(d);
}

TEST(CmdRender, BadInputIsOneLineExitTwoAndKeepsExistingOutput) {
  fs::path d = tempDir();
  std::string exr = (d / "keep.exr").string();
  { std::ofstream(exr) << "precious"; }
  std::string badEnv = (d / "env.hdr").string();
  { std::ofstream(badEnv) << "not an image"; }
  std::string badScene = (d / "broken.gltf").string();
  { std::ofstream(badScene) << "{ not json"; }
  const std::string out = " --offline " + exr + " ";
  for (std::string args : {
           "--bogus" + out + kCornell,
           "--mode path --spp -4" + out + kCornell,
           "--mode path --spp 0" + out + kCornell,
           "--time -1" + out + kCornell,
           "--mode fancy" + out + kCornell,
           "--env " + badEnv + out + kCornell,
           "--env " + (d / "missing.exr").string() + out + kCornell,
           out + badScene,
           out + (d / "missing.gltf").string(),
           "--offline " + (d / "no_such_dir" / "x.exr").string() + " " + kCornell,
           "--offline " + d.string() + " " + kCornell,
           "--camera nine" + out + kCornell,
       }) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << "\n" << r.out;
    EXPECT_EQ(slurp(exr), "precious") << args;
  }
  // No temporaries left behind next to the output.
  for (auto& e : fs::directory_iterator(d))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  fs::remove_all(d);
}

TEST(CmdRender, EnvironmentMapLightsAWhiteFurnace) {
  fs::path d = tempDir();
  std::string env = (d / "sky.exr").string(), gltf = (d / "ball.gltf").string(),
              exr = (d / "ball.exr").string();
  image::writeExr(env, {8, 4, {{"", {"R", "G", "B"}, std::vector<float>(8 * 4 * 3, 0.5f)}}},
                image::ExrPixelType::Float);
  test::GltfWriter g;
  g.sphere({0, 0, 0}, 1.f, g.material(test::GltfWriter::diffuse(glm::vec3(1.f))));
  g.camera({0, 0, 4}, {0, 0, 0}, 0.7f);
  g.write(gltf);
  Result r = run("--mode path --env " + env + " --width 8 --spp 128 --quiet --offline " + exr + " " + gltf);
  ASSERT_EQ(r.code, 0) << r.out;
  image::RgbImage img = image::readExrRgb(exr);
  double sum = 0;
  for (float v : img.rgb) sum += v;
  EXPECT_NEAR(sum / img.rgb.size(), 0.5, 0.01);
  fs::remove_all(d);
}

// --time alone: the progress line counts samples without a target ("12 spp", not
// "12/16777216 spp"); with --spp it shows the target. The format is README's "Progress".
TEST(CmdRender, ProgressLineShowsTheBudgetGiven) {
  fs::path d = tempDir();
  std::string exr = (d / "p.exr").string();
  Result timeOnly = run("--mode path --width 16 --time 0.5 --offline " + exr + " " + kCornell);
  ASSERT_EQ(timeOnly.code, 0) << timeOnly.out;
  EXPECT_EQ(timeOnly.out.find("16777216"), std::string::npos) << timeOnly.out;
  EXPECT_TRUE(std::regex_search(
      timeOnly.out, std::regex("osr-vk: [0-9]+ spp, [0-9.]+ s elapsed, ~[0-9.]+ s remaining")))
      << timeOnly.out;
  Result spp = run("--mode path --width 16 --spp 3 --offline " + exr + " " + kCornell);
  ASSERT_EQ(spp.code, 0) << spp.out;
  EXPECT_NE(spp.out.find("osr-vk: 3/3 spp, "), std::string::npos) << spp.out;
  fs::remove_all(d);
}

// A scene without lights (most glTF sample models): a one-line warning, and the neutral sky
// lights it: a diffuse ball of albedo 0.8 under a sky of at least kNeutralSkyNadir everywhere
// is at least 0.8 x that bright, and under a key of kNeutralSkyKey over about 0.37 sr (cos^16)
// plus the sky, no brighter than 0.8 x (zenith + key x 0.37 / pi); --env none renders it
// black without a warning.
TEST(CmdRender, SceneWithoutLightsGetsANeutralSkyAndAWarning) {
  fs::path d = tempDir();
  std::string gltf = (d / "dark.gltf").string(), exr = (d / "dark.exr").string();
  test::GltfWriter g;
  g.sphere({0, 0, 0}, 1.f, g.material(test::GltfWriter::diffuse(glm::vec3(0.8f))));
  g.camera({0, 0, 4}, {0, 0, 0}, 0.5f);
  g.write(gltf);
  auto meanOf = [](const image::RgbImage& img) {
    double sum = 0;
    for (float v : img.rgb) sum += v;
    return sum / double(img.rgb.size());
  };
  Result lit = run("--mode path --width 8 --spp 16 --quiet --offline " + exr + " " + gltf);
  ASSERT_EQ(lit.code, 0) << lit.out;
  EXPECT_EQ(lit.out, "osr-vk: warning: " + gltf +
                         ": the scene has no lights (no emissive surfaces, no KHR_lights_punctual, "
                         "no --env); lighting it with a neutral sky (--env none: leave it unlit)\n");
  const double m = meanOf(image::readExrRgb(exr));
  EXPECT_GT(m, 0.8 * scene::kNeutralSkyNadir);
  EXPECT_LT(m, 0.8 * (scene::kNeutralSkyZenith + scene::kNeutralSkyKey * 0.37 / 3.14159));
  Result dark = run("--mode path --width 8 --spp 4 --quiet --env none --offline " + exr + " " + gltf);
  ASSERT_EQ(dark.code, 0) << dark.out;
  EXPECT_EQ(dark.out, "");
  EXPECT_EQ(meanOf(image::readExrRgb(exr)), 0.0);
  // A scene with lights gets no sky and no warning.
  Result cornell = run("--mode path --width 8 --spp 1 --quiet --offline " + exr + " " + kCornell);
  EXPECT_EQ(cornell.out, "");
  fs::remove_all(d);
}

// 3840 x 2160 on lavapipe: the film (760 MiB of 96-byte pixels) is bound in windows of at most
// maxStorageBufferRange (128 MiB), so every window must be traced: the depth layer sees the
// floor in the bottom rows and the walls in the last window's columns, and nothing is NaN.
TEST(CmdRender, RendersFourKAtOneSample) {
  fs::path d = tempDir();
  std::string exr = (d / "4k.exr").string();
  Result r = run("--mode path --width 3840 --height 2160 --spp 1 --quiet --offline " + exr + " " + kCornell);
  ASSERT_EQ(r.code, 0) << r.out;
  Imf::InputFile f(exr.c_str());
  const Imath::Box2i dw = f.header().dataWindow();
  EXPECT_EQ(dw.max.x - dw.min.x + 1, 3840);
  EXPECT_EQ(dw.max.y - dw.min.y + 1, 2160);
  image::RgbImage img = image::readExrRgb(exr);
  // Mean of each band of 270 rows (8 bands; the windows are 1 Mi pixels = 273 rows) over the
  // middle columns (the box; the sides are black, outside the square camera's view).
  for (int band = 0; band < 8; ++band) {
    double sum = 0;
    size_t n = 0;
    for (int y = band * 270; y < (band + 1) * 270; ++y)
      for (int x = 1300; x < 2540; ++x, ++n)
        for (int c = 0; c < 3; ++c) {
          const float v = img.rgb[(size_t(y) * 3840 + x) * 3 + c];
          ASSERT_TRUE(std::isfinite(v)) << x << "," << y;
          sum += v;
        }
    EXPECT_GT(sum / n, 0.05) << "band " << band << " is black";
  }
  fs::remove_all(d);
}
