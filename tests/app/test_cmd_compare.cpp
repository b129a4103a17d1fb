// `osr-vk compare` as a user runs it: the JSON line, and exit 2 with one line on bad input.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/cli_runner.h"
#include "common/vk_test.h"
#include "image/image_io.h"

using namespace osr;
namespace fs = std::filesystem;

namespace {
using Result = test::CliResult;
Result run(const std::string& args) {
  return test::runOsrVk(args);
}
}  // namespace

TEST(CmdCompare, PrintsOneJsonLine) {
  std::string ref = test::referencePath("cornell/cornell_cycles_4096spp.exr");
  Result r = run("compare " + ref + " " + ref);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("{\"relmse\": 0, \"psnr\": null, \"ssim\": 1, \"lum_ratio\": 1"), 0u)
      << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1);
}

TEST(CmdCompare, BadInputExitsTwoWithOneLine) {
  fs::path d = fs::temp_directory_path() / ("osr_test_cmp_" + std::to_string(::getpid()));
  fs::create_directories(d);
  std::string small = (d / "small.exr").string(), junk = (d / "junk.exr").string();
  image::writeExr(small, {2, 2, {{"", {"R", "G", "B"}, std::vector<float>(12, 1.f)}}},
                  image::ExrPixelType::Half);
  { std::ofstream(junk) << "not an exr"; }
  std::string ref = test::referencePath("cornell/cornell_cycles_4096spp.exr");
  for (std::string args :
       {"compare " + small + " " + ref, "compare " + junk + " " + ref, "compare " + ref,
        "compare " + ref + " " + (d / "nope.exr").string(), "compare --bogus " + ref + " " + ref}) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << ": " << r.out;
  }
  fs::remove_all(d);
}

TEST(CmdCompare, BoxFiltersATestTwiceTheReferenceSize) {
  fs::path d = fs::temp_directory_path() / ("osr_test_cmp2_" + std::to_string(::getpid()));
  fs::create_directories(d);
  // A 4 x 4 test whose 2 x 2 blocks average to the 2 x 2 reference exactly.
  std::vector<float> big(4 * 4 * 3), small(2 * 2 * 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c)
        big[(y * 4 + x) * 3 + c] = float((x / 2) + 2 * (y / 2)) + ((x + y) % 2 ? 0.5f : -0.5f);
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 3; ++c) small[i * 3 + c] = float(i);
  const std::string bigPath = (d / "big.exr").string(), smallPath = (d / "small.exr").string(),
                    oddPath = (d / "odd.exr").string();
  image::writeExr(bigPath, {4, 4, {{"", {"R", "G", "B"}, big}}}, image::ExrPixelType::Float);
  image::writeExr(smallPath, {2, 2, {{"", {"R", "G", "B"}, small}}}, image::ExrPixelType::Float);
  image::writeExr(oddPath, {4, 2, {{"", {"R", "G", "B"}, std::vector<float>(24, 1.f)}}},
                  image::ExrPixelType::Float);
  Result r = run("compare " + bigPath + " " + smallPath);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("{\"relmse\": 0,"), 0u) << r.out;
  EXPECT_NE(r.out.find("\"test_downsampled_by\": 2}"), std::string::npos) << r.out;
  // Twice as wide but as high: not a box filter's multiple, refused.
  r = run("compare " + oddPath + " " + smallPath);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("differs from"), std::string::npos) << r.out;
  fs::remove_all(d);
}
