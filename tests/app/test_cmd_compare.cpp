// `osr-vk compare` as a user runs it: the JSON line, and exit 2 with one line on bad input.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/cli_runner.h"
#include "image/image_io.h"
#include "common/vk_test.h"

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
