// `osr-vk maps` as the training pipeline runs it: .npy files whose headers and shapes parse,
// maps that obey the channel conventions (DESIGN.md "Hemisphere maps"), a reference whose mean
// radiance agrees with the independent one-shot input's, files NumPy loads (when the system
// python has NumPy), reproducible points, and bad input: one line, exit 2, no files left.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include "app/cli_runner.h"
#include "common/vk_test.h"

using namespace osr;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = test::referencePath("cornell/cornell.gltf");

std::string slurp(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

struct Npy {
  std::string descr;
  std::vector<size_t> shape;
  std::string data;  // raw little-endian elements
  size_t count() const {
    size_t n = 1;
    for (size_t d : shape) n *= d;
    return n;
  }
  template <typename T>
  T at(size_t i) const {
    T v;
    std::memcpy(&v, data.data() + i * sizeof(T), sizeof(T));
    return v;
  }
};

// Parses a format 1.0 .npy file as written by osr-vk, failing the test on any deviation.
Npy readNpy(const fs::path& path) {
  Npy n;
  const std::string b = slurp(path);
  EXPECT_GE(b.size(), 10u) << path;
  if (b.size() < 10) return n;
  EXPECT_EQ(b.substr(0, 6), "\x93NUMPY") << path;
  EXPECT_EQ(b[6], 1);
  EXPECT_EQ(b[7], 0);
  const size_t hlen = uint8_t(b[8]) | size_t(uint8_t(b[9])) << 8;
  EXPECT_EQ((10 + hlen) % 64, 0u) << path;
  const std::string h = b.substr(10, hlen);
  EXPECT_EQ(h.back(), '\n');
  std::smatch m;
  const std::regex re(R"(^\{'descr': '(<[fi]4)', 'fortran_order': False, 'shape': \(([0-9, ]*)\), \} *\n$)");
  EXPECT_TRUE(std::regex_match(h, m, re)) << h;
  if (m.empty()) return n;
  n.descr = m[1];
  const std::string dims = m[2];
  for (size_t at = 0; at < dims.size();) {
    size_t end = dims.find(',', at);
    if (end == std::string::npos) end = dims.size();
    if (end > at) n.shape.push_back(std::stoul(dims.substr(at, end - at)));
    at = end + 1;
    while (at < dims.size() && dims[at] == ' ') ++at;
  }
  n.data = b.substr(10 + hlen);
  EXPECT_EQ(n.data.size(), n.count() * 4) << path;
  return n;
}

bool systemNumpy() {
  return std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") == 0;
}

}  // namespace

TEST(CmdMaps, GridWithReferenceGivesConsistentMaps) {
  const fs::path d = test::tempDir("cmd_maps") / "grid";
  fs::remove_all(d);
  test::CliResult r = test::runOsrVk("maps " + kCornell + " --out " + d.string() +
                                     " --width 32 --grid 8 --views 2 --reference-spp 16 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out, "");
  Npy in = readNpy(d / "input.npy"), tg = readNpy(d / "target.npy"), pts = readNpy(d / "points.npy");
  EXPECT_EQ(in.descr, "<f4");
  EXPECT_EQ(tg.descr, "<f4");
  EXPECT_EQ(pts.descr, "<i4");
  ASSERT_EQ(pts.shape.size(), 2u);
  const size_t n = pts.shape[0];
  EXPECT_EQ(pts.shape[1], 3u);
  // cornell is closed: every cell of both 32 x 32 views (4 x 4 cells of 8) sees a surface.
  EXPECT_EQ(n, 32u);
  EXPECT_EQ(in.shape, (std::vector<size_t>{n, 7, 32, 32}));
  EXPECT_EQ(tg.shape, (std::vector<size_t>{n, 3, 32, 32}));
  ASSERT_EQ(in.count(), n * 7 * 1024);
  ASSERT_EQ(tg.count(), n * 3 * 1024);
  for (size_t i = 0; i < n; ++i) {  // view, then a pixel inside its 8 x 8 cell
    const int32_t v = pts.at<int32_t>(3 * i), x = pts.at<int32_t>(3 * i + 1), y = pts.at<int32_t>(3 * i + 2);
    EXPECT_EQ(v, int32_t(i / 16));
    EXPECT_EQ(x / 8 + 4 * (y / 8), int32_t(i % 16)) << x << "," << y;
  }
  double inSum = 0, tgSum = 0;
  size_t hits = 0, bad = 0;
  for (size_t m = 0; m < n; ++m)
    for (size_t t = 0; t < 1024; ++t) {
      auto ch = [&](size_t c) { return in.at<float>((m * 7 + c) * 1024 + t); };
      for (size_t c = 0; c < 3; ++c) {
        const float a = ch(c), b = tg.at<float>((m * 3 + c) * 1024 + t);
        if (!(std::isfinite(a) && a >= 0.f && std::isfinite(b) && b >= 0.f)) ++bad;
        inSum += a;
        tgSum += b;
      }
      const float dist = ch(6);
      const double len = std::sqrt(double(ch(3)) * ch(3) + double(ch(4)) * ch(4) + double(ch(5)) * ch(5));
      if (dist > 0.f) {
        ++hits;
        if (std::fabs(len - 1.0) > 1e-3) ++bad;
      } else if (dist != -1.f || len != 0.0) {  // (0 is below-surface; cornell is flat)
        ++bad;
      }
    }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(hits, n * 1024 / 2);  // the box is open only at the front
  EXPECT_GT(tgSum, 0.0);
  EXPECT_NEAR(inSum / tgSum, 1.0, 0.1) << inSum << " vs " << tgSum;

  const std::string index = slurp(d / "index.json");
  for (const char* field : {"\"count\": 32", "\"grid\": 8", "\"views\": 2", "\"reference_spp\": 16",
                            "\"mapping\": \"concentric\"", "\"width\": 32", "\"height\": 32",
                            "\"distance\"", "\"version\": \"", "cornell.gltf"})
    EXPECT_NE(index.find(field), std::string::npos) << field << "\n" << index;
  for (const auto& e : fs::directory_iterator(d))  // no temporary left over
    EXPECT_NE(e.path().filename().string()[0], '.') << e.path();

  if (systemNumpy()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6e", inSum);
    const std::string py =
        "import numpy as np, sys; d=sys.argv[1]; "
        "i=np.load(d+'/input.npy', mmap_mode='r'); t=np.load(d+'/target.npy', mmap_mode='r'); "
        "p=np.load(d+'/points.npy', mmap_mode='r'); "
        "assert isinstance(i, np.memmap) and i.dtype==np.float32 and i.shape==(32,7,32,32), i.shape; "
        "assert t.dtype==np.float32 and t.shape==(32,3,32,32) and p.dtype==np.int32 and p.shape==(32,3); "
        "s=float(i[:, :3].astype(np.float64).sum()); assert abs(s/" + std::string(buf) +
        "-1) < 1e-5, s; print('ok')";
    const std::string cmd = "/usr/bin/python3 -c \"" + py + "\" " + d.string() + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    std::string out;
    char line[512];
    while (fgets(line, sizeof line, p)) out += line;
    EXPECT_EQ(pclose(p), 0) << out;
    EXPECT_EQ(out, "ok\n");
  }
  fs::remove_all(d);
}

TEST(CmdMaps, PixelListAndReproducibleGrid) {
  const fs::path d = test::tempDir("cmd_maps") / "pixels";
  fs::remove_all(d);
  auto run = [&](const std::string& opts) {
    test::CliResult r = test::runOsrVk("maps " + kCornell + " --out " + d.string() +
                                       " --width 16 --height 12 --quiet " + opts);
    EXPECT_EQ(r.code, 0) << opts << ": " << r.out;
  };
  // At 4:3 the square camera sees past the box's walls: corner pixel 15,11 has no surface and
  // is skipped in both views.
  run("--pixels '3,4;15,11' --views 2 --reference-spp 2");
  Npy pts = readNpy(d / "points.npy");
  std::vector<int32_t> got;
  for (size_t i = 0; i < pts.count(); ++i) got.push_back(pts.at<int32_t>(i));
  EXPECT_EQ(got, (std::vector<int32_t>{0, 3, 4, 1, 3, 4}));
  EXPECT_EQ(readNpy(d / "input.npy").shape, (std::vector<size_t>{2, 7, 32, 32}));
  EXPECT_EQ(readNpy(d / "target.npy").shape, (std::vector<size_t>{2, 3, 32, 32}));
  // Without a reference the earlier target.npy goes: it would not match input.npy.
  run("--grid 5 --seed 9");
  EXPECT_FALSE(fs::exists(d / "target.npy"));
  const std::string points = slurp(d / "points.npy"), input = slurp(d / "input.npy");
  // At most one point per 5 x 5 cell (4 x 3 cells, the last ones clipped), fewer where the
  // cell's pixel sees no surface.
  pts = readNpy(d / "points.npy");
  ASSERT_EQ(pts.shape.size(), 2u);
  EXPECT_GT(pts.shape[0], 0u);
  std::set<int32_t> cells;
  for (size_t i = 0; i < pts.shape[0]; ++i) {
    const int32_t x = pts.at<int32_t>(3 * i + 1), y = pts.at<int32_t>(3 * i + 2);
    EXPECT_TRUE(x >= 0 && x < 16 && y >= 0 && y < 12) << x << "," << y;
    EXPECT_TRUE(cells.insert(x / 5 + 4 * (y / 5)).second) << x << "," << y;
  }
  run("--grid 5 --seed 9");
  EXPECT_EQ(slurp(d / "points.npy"), points);
  EXPECT_EQ(slurp(d / "input.npy"), input);
  run("--grid 5 --seed 10");
  EXPECT_NE(slurp(d / "points.npy"), points);
  fs::remove_all(d);
}

TEST(CmdMaps, BadInputIsOneLineExitTwoAndLeavesNoFiles) {
  const fs::path base = test::tempDir("cmd_maps") / "bad";
  fs::remove_all(base);
  fs::create_directories(base);
  const fs::path file = base / "a_file", dir = base / "out";
  { std::ofstream(file) << "keep"; }
  const std::string out = " --out " + dir.string() + " --width 16 ";
  const std::pair<std::string, std::string> cases[] = {
      {" --out " + file.string() + " --grid 4", "is not a folder"},
      {out + "--pixels '1;2'", "is not x,y"},
      {out + "--pixels '1,2;3,-4'", "is not x,y"},
      {out + "--pixels '1,2,3'", "is not x,y"},
      {out + "--pixels 16,0", "outside the 16x16 image"},
      {out + "--grid 4 --pixels 1,1", "not both"},
      {out, "--grid R or --pixels"},
      {" --width 16 --grid 4", "--out"},
      {out + "--grid 0", "--grid"},
      {out + "--grid 4 --env /nonexistent.hdr", "nonexistent.hdr"},
      {out + "--grid 4 --bogus", "--bogus"},
  };
  for (const auto& [args, problem] : cases) {
    test::CliResult r = test::runOsrVk("maps " + kCornell + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << ": " << r.out;
    EXPECT_NE(r.out.find(problem), std::string::npos) << args << ": " << r.out;
    EXPECT_FALSE(fs::exists(dir)) << args;
    EXPECT_EQ(slurp(file), "keep");
  }
  test::CliResult r = test::runOsrVk("maps --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind("usage: osr-vk maps", 0), 0u) << r.out;
  fs::remove_all(base);
}
