// osr-vk unet from outside: the committed PyTorch golden batch through the CLI matches
// PyTorch's output; bad input gives one stderr line and exit code 2.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "common/vk_test.h"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exitCode;
  std::string err;
};

CliRun runCli(const std::string& args) {
  const fs::path err = fs::temp_directory_path() / ("osr_cli_unet_" + std::to_string(::getpid()) + ".err");
  const std::string cmd = std::string(OSR_BINARY_DIR) + "/osr-vk unet " + args + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  std::ifstream f(err);
  CliRun r{WEXITSTATUS(status), {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()}};
  fs::remove(err);
  return r;
}

std::vector<float> readFloats(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::vector<char> b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::vector<float> v(b.size() / 4);
  std::memcpy(v.data(), b.data(), v.size() * 4);
  return v;
}

}  // namespace

TEST(CmdUnet, GoldenBatchMatchesPyTorch) {
  const std::string out = (fs::temp_directory_path() / ("osr_cli_pred_" + std::to_string(::getpid()) + ".f32")).string();
  CliRun r = runCli("--quiet --weights " + osr::test::dataPath("unet_k8.osrw") + " --in " +
                 osr::test::dataPath("unet_k8_golden/input.f32") + " --out " + out);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::vector<float> got = readFloats(out), want = readFloats(osr::test::dataPath("unet_k8_golden/output.f32"));
  ASSERT_EQ(got.size(), want.size());
  double err = 0;
  for (size_t i = 0; i < got.size(); ++i) err = std::max(err, double(std::fabs(got[i] - want[i])));
  EXPECT_LE(err, 1e-4);
  fs::remove(out);
}

TEST(CmdUnet, BadInputIsOneLineAndExitTwo) {
  const std::string weights = osr::test::dataPath("unet_k8.osrw");
  const std::string maps = osr::test::dataPath("unet_k8_golden/input.f32");
  // Input not a whole number of maps: the golden output file (3 x 3 x 32 x 32 floats).
  const std::string notMaps = osr::test::dataPath("unet_k8_golden/output.f32");
  const std::pair<std::string, std::string> cases[] = {
      {"--weights " + weights + " --in " + notMaps + " --out /dev/null",
       "is not a positive multiple"},
      {"--weights " + maps + " --in " + maps + " --out /dev/null", "bad magic"},
      {"--weights /nonexistent.osrw --in " + maps + " --out /dev/null", "file not found"},
      {"--weights " + weights + " --in " + maps, "usage"},
      {"--weights " + weights + " --in " + maps + " --out /dev/null --bogus", "--bogus"},
  };
  for (const auto& [args, problem] : cases) {
    CliRun r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
  }
}

// --out naming a file the command reads wrote the predictions over it (the user's maps or
// weights, gone): refused before any work, the file untouched.
TEST(CmdUnet, OutputThatIsAnInputIsRefused) {
  const fs::path dir = osr::test::tempDir("cmd_unet");
  const fs::path maps = dir / "maps.f32", weights = dir / "w.osrw";
  fs::copy_file(osr::test::dataPath("unet_k8_golden/input.f32"), maps,
                fs::copy_options::overwrite_existing);
  fs::copy_file(osr::test::dataPath("unet_k8.osrw"), weights, fs::copy_options::overwrite_existing);
  const auto before = readFloats(maps.string());
  const auto weightsBefore = fs::file_size(weights);
  const std::string in = " --weights " + weights.string() + " --in " + maps.string();
  for (const auto& [out, role] :
       {std::pair{maps, "the --in maps"}, {weights, "the --weights file"}}) {
    CliRun r = runCli(in + " --out " + out.string());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(r.err, "osr-vk: --out " + out.string() + ": is " + role +
                         ", which this command reads; refusing to overwrite it\n");
  }
  EXPECT_EQ(readFloats(maps.string()), before);
  EXPECT_EQ(fs::file_size(weights), weightsBefore);
}
