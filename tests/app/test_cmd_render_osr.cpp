// osr-vk --mode osr on bad input: missing, corrupt or mismatched weights, an unknown denoiser, a
// grid option out of range, OSR options without --mode osr: one line on stderr naming the
// problem, exit 2, and the output files (which exist beforehand) untouched. And a good run
// writes every layer.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/vk_test.h"
#include "image/image_io.h"

namespace fs = std::filesystem;

namespace {

struct Outcome {
  int exitCode;
  std::string err;
};

Outcome run(const std::string& args) {
  fs::path errFile = osr::test::tempDir("cmd_render_osr") / "stderr.txt";
  std::string cmd =
      std::string(OSR_BINARY_DIR) + "/osr-vk " + args + " >/dev/null 2>" + errFile.string();
  int status = std::system(cmd.c_str());
  std::ifstream in(errFile);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), ss.str()};
}

std::string cornell() {
  return osr::test::referencePath("cornell/cornell.gltf");
}

}  // namespace

TEST(CmdRenderOsr, BadInputIsOneLineExitTwoAndTouchesNoOutput) {
  fs::path dir = osr::test::tempDir("cmd_render_osr");
  fs::path exr = dir / "keep.exr", png = dir / "keep.png";
  for (const fs::path& p : {exr, png}) std::ofstream(p) << "the user's file";
  fs::path corrupt = dir / "corrupt.osrw";
  std::ofstream(corrupt) << "not a weights file";
  // A valid file whose header names another mapping: the packed test network, edited.
  fs::path otherMapping = dir / "latlong.osrw";
  {
    std::ifstream in(osr::test::dataPath("unet_k8.osrw"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    auto at = bytes.find("concentric");
    ASSERT_NE(at, std::string::npos);
    bytes.replace(at, 10, "latlongxyz");
    std::ofstream(otherMapping, std::ios::binary) << bytes;
  }
  const std::string out =
      " --offline '" + exr.string() + "' --png '" + png.string() + "' --width 16 ";
  struct Case {
    std::string args, mustMention;
  } cases[] = {
      {"--mode osr --weights " + (dir / "missing.osrw").string(), "missing.osrw"},
      {"--mode osr --weights " + corrupt.string(), "corrupt.osrw"},
      {"--mode osr --weights " + otherMapping.string(), "latlong.osrw"},
      {"--mode osr --denoiser median", "--denoiser"},
      {"--mode osr --grid-start 0", "--grid-start"},
      {"--mode osr --grid-start 8 --grid-min 16", "--grid-min"},
      {"--mode osr --grid-min 1000", "--grid-min"},
      {"--mode osr --spp 4", "--spp"},
      {"--mode path --passes 4", "--passes"},
      {"--mode osr --residual-spp x", "--residual-spp"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    Outcome r = run(c.args + out + cornell());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    EXPECT_NE(r.err.find(c.mustMention), std::string::npos) << r.err;
    for (const fs::path& p : {exr, png}) {
      std::ifstream in(p);
      std::string content((std::istreambuf_iterator<char>(in)), {});
      EXPECT_EQ(content, "the user's file") << p;
    }
  }
}

// --dump-maps onto something that cannot be a folder used to fail after the whole render,
// exit 1 with a raw filesystem message, after writing the other outputs: now one line, exit 2,
// before any work, and the user's files untouched. In the viewer, which never dumps maps, the
// option is refused rather than ignored.
TEST(CmdRenderOsr, DumpMapsThatCannotBeAFolderIsBadInput) {
  fs::path dir = osr::test::tempDir("cmd_render_osr_dump");
  fs::path file = dir / "a_file", png = dir / "keep.png";
  for (const fs::path& p : {file, png}) std::ofstream(p) << "the user's file";
  for (const fs::path& target : {file, file / "below"}) {
    SCOPED_TRACE(target);
    Outcome r = run("--mode osr --passes 1 --width 16 --quiet --png '" + png.string() + "' --dump-maps '" +
                    target.string() + "' " + cornell());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(r.err.rfind("osr-vk: --dump-maps: " + target.string(), 0), 0u) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    for (const fs::path& p : {file, png}) {
      std::ifstream in(p);
      EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), {}), "the user's file") << p;
    }
  }
  Outcome live = run("--mode osr --dump-maps '" + (dir / "maps").string() + "' " + cornell());
  EXPECT_EQ(live.exitCode, 2) << live.err;
  EXPECT_EQ(live.err,
            "osr-vk: --dump-maps: an option of --offline/--png renders (the viewer "
            "saves with S)\n");
}

TEST(CmdRenderOsr, WritesEveryLayerAndTheMapAtlases) {
  fs::path dir = osr::test::tempDir("cmd_render_osr");
  fs::path exr = dir / "osr.exr", maps = dir / "maps";
  fs::remove_all(maps);
  Outcome r = run("--mode osr --passes 3 --quiet --width 32 --weights " +
                  osr::test::dataPath("unet_k8.osrw") + " --dump-maps '" + maps.string() +
                  "' --offline '" + exr.string() + "' " + cornell());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  Imf::InputFile file(exr.c_str());
  const Imf::ChannelList& channels = file.header().channels();
  for (const char* c : {"R", "G", "B", "direct.R", "indirect.G", "albedo.B", "normal.X", "depth.Z"})
    EXPECT_NE(channels.findChannel(c), nullptr) << "channel " << c;
  for (const char* f : {"oneshot.png", "clean.png", "grid.png"})
    EXPECT_TRUE(fs::exists(maps / f)) << f;
}

// OSR's map denoiser is the blur by default; `--denoiser unet` without --weights runs the model
// built into the executable (models/osr_unet.osrw, docs/training.md), whose header states the
// conventions this renderer feeds it.
TEST(CmdRenderOsr, BlurByDefaultAndTheBuiltInModelRuns) {
  fs::path dir = osr::test::tempDir("cmd_render_osr");
  fs::path exr = dir / "builtin.exr";
  Outcome byDefault = run("--mode osr --passes 2 --width 32 --offline '" + exr.string() + "' " +
                          cornell());
  ASSERT_EQ(byDefault.exitCode, 0) << byDefault.err;
  EXPECT_NE(byDefault.err.find("2 passes in"), std::string::npos) << byDefault.err;
  EXPECT_NE(byDefault.err.find("denoise"), std::string::npos) << byDefault.err;
  EXPECT_EQ(byDefault.err.find(" unet "), std::string::npos) << "the blur is the default denoiser";
  Outcome unet = run("--mode osr --denoiser unet --passes 2 --width 32 --offline '" + exr.string() + "' " +
                     cornell());
  ASSERT_EQ(unet.exitCode, 0) << unet.err;
  EXPECT_NE(unet.err.find(", unet "), std::string::npos) << unet.err;
}

// An image larger than one binding of OSR's per-pixel buffers (1280 x 832 pixels of 128-byte
// G-buffer records is 130 MiB, over lavapipe's 128 MiB maxStorageBufferRange): the passes bind
// windows. The first-hit albedo OSR writes equals the path tracer's, band by band (a window
// bound at the wrong offset shifts or blanks rows), and across the window edge at row 819
// (1 Mi pixels) the image changes as the path-traced one does.
TEST(CmdRenderOsr, ImagesLargerThanOneBindingRenderInWindows) {
  fs::path dir = osr::test::tempDir("cmd_render_osr_windows");
  const std::string osrExr = (dir / "osr.exr").string(), pathExr = (dir / "path.exr").string();
  const std::string size = " --width 1280 --height 832 --quiet ";
  Outcome osrRun = run("--mode osr --passes 1 --grid-start 32 --grid-min 32 --direct-spp 1 "
                       "--residual-spp 0 --offline " + osrExr + size + cornell());
  ASSERT_EQ(osrRun.exitCode, 0) << osrRun.err;
  Outcome pathRun = run("--mode path --spp 4 --offline " + pathExr + size + cornell());
  ASSERT_EQ(pathRun.exitCode, 0) << pathRun.err;
  const osr::image::RgbImage osrAlbedo = osr::image::readExrRgb(osrExr, "albedo");
  const osr::image::RgbImage pathAlbedo = osr::image::readExrRgb(pathExr, "albedo");
  const int w = osrAlbedo.width, h = osrAlbedo.height, pw = pathAlbedo.width, ph = pathAlbedo.height;
  const std::vector<float>& albedo = osrAlbedo.rgb;
  const std::vector<float>& reference = pathAlbedo.rgb;
  ASSERT_EQ(w, 1280);
  ASSERT_EQ(h, 832);
  ASSERT_EQ(pw, w);
  ASSERT_EQ(ph, h);
  for (int y0 = 0; y0 < h; y0 += 16) {
    double diff = 0, sum = 0;
    for (int y = y0; y < y0 + 16; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          const size_t i = (size_t(y) * w + x) * 3 + c;
          diff += std::abs(albedo[i] - reference[i]);
          sum += reference[i];
        }
    EXPECT_LT(diff, 0.05 * sum + 1.0) << "rows " << y0 << "-" << y0 + 15;
  }
  const std::vector<float> osrImage = osr::image::readExrRgb(osrExr).rgb,
                           pathImage = osr::image::readExrRgb(pathExr).rgb;
  auto rowsMean = [&](const std::vector<float>& img, int y0, int y1) {
    double sum = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w * 3; ++x) sum += img[size_t(y) * w * 3 + x];
    return sum / (double(y1 - y0) * w * 3);
  };
  const double osrRatio = rowsMean(osrImage, 821, 831) / rowsMean(osrImage, 808, 818);
  const double pathRatio = rowsMean(pathImage, 821, 831) / rowsMean(pathImage, 808, 818);
  EXPECT_NEAR(osrRatio / pathRatio, 1.0, 0.1)
      << "below / above row 819: osr " << osrRatio << ", path " << pathRatio;
  fs::remove_all(dir);
}

// A pass can take minutes (4K on lavapipe): the CLI runs the first pass in slices, so progress
// lines come during it, and a --time that ends inside it stops it there and says the image is
// unfinished (tests/app/test_cmd_render_stop.cpp: the EXR and signals).
TEST(CmdRenderOsr, TheFirstPassShowsProgressAndTimeStopsInsideIt) {
  fs::path dir = osr::test::tempDir("cmd_render_osr");
  fs::path exr = dir / "first_pass.exr";
  // 256 x 256 pixels: the first pass in 32 slices.
  Outcome r = run("--mode osr --time 0.001 --width 256 --offline '" + exr.string() + "' " + cornell());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(exr));
  EXPECT_NE(r.err.find("osr-vk: 0 passes (+3% of the next), "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("osr-vk: warning: --time stopped the first pass at 3% after "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(", 0 passes in"), std::string::npos) << r.err;
}
