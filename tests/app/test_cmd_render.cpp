// `osr-vk [options] scene.gltf` as a user runs it: the layers of the EXR, --quiet, --time, and
// bad input (unknown flags, negative spp, unwritable output, unreadable environment map, bad
// mode): one stderr line, exit 2, and an existing output file left untouched.
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <tuple>

#include "app/cli_runner.h"
#include "image/image_io.h"
#include "common/vk_test.h"
#include "pt/gltf_writer.h"

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

TEST(CmdRender, TimeLimitStopsTheRenderWithProgress) {
  fs::path d = tempDir();
  std::string exr = (d / "t.exr").string();
  auto t0 = std::chrono::steady_clock::now();
  Result r = run("--width 16 --spp 1000000 --time 1 --offline " + exr + " " + kCornell);
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_LT(s, 30.0);
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
           "--spp -4" + out + kCornell,
           "--spp 0" + out + kCornell,
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
  Result r = run("--env " + env + " --width 8 --spp 128 --quiet --offline " + exr + " " + gltf);
  ASSERT_EQ(r.code, 0) << r.out;
  image::RgbImage img = image::readExrRgb(exr);
  double sum = 0;
  for (float v : img.rgb) sum += v;
  EXPECT_NEAR(sum / img.rgb.size(), 0.5, 0.01);
  fs::remove_all(d);
}
