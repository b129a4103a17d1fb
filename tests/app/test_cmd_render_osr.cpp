// osr-vk --mode osr on bad input: missing, corrupt or mismatched weights, an unknown denoiser, a
// grid option out of range, OSR options without --mode osr: one line on stderr naming the
// problem, exit 2, and the output files (which exist beforehand) untouched. And a good run
// writes every layer.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/vk_test.h"

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
      {"--mode osr --denoiser unet", "--denoiser unet"},
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
