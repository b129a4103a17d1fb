// Outputs never destroy inputs (app/output_paths.h): sameFile by identity (relative paths,
// symlinks, hard links, paths not created yet), checkOutputs' refusals, and osr-vk itself on
// the cases a person runs into: every one exits 2 with one stderr line before rendering and
// leaves every file as it was.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "app/cli_runner.h"
#include "app/output_paths.h"
#include "common/error.h"
#include "common/test_paths.h"

using namespace osr;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

void writeFile(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A copy of the cornell scene (glTF + external .bin) and an environment map in a fresh
// directory, so that a failing test cannot damage the shipped files.
struct Workspace {
  fs::path dir = test::tempDir("output_paths");
  fs::path scene = dir / "cornell.gltf", bin = dir / "cornell.bin", env = dir / "sky.exr",
           weights = dir / "model.osrw";
  Workspace() {
    fs::copy_file(test::referencePath("cornell/cornell.gltf"), scene);
    fs::copy_file(test::referencePath("cornell/cornell.bin"), bin);
    fs::copy_file(test::referencePath("cornell/cornell_cycles_4096spp.exr"), env);
    writeFile(weights, "not really weights");
  }
  ~Workspace() { fs::remove_all(dir); }
};

}  // namespace

TEST(OutputPaths, SameFileByIdentityNotSpelling) {
  Workspace w;
  const fs::path sub = w.dir / "sub";
  fs::create_directory(sub);
  fs::create_symlink(w.scene, w.dir / "link.exr");
  fs::create_hard_link(w.bin, w.dir / "hard.exr");
  EXPECT_TRUE(app::sameFile(w.scene.string(), w.scene.string()));
  EXPECT_TRUE(app::sameFile((sub / ".." / "cornell.gltf").string(), w.scene.string()));
  EXPECT_TRUE(app::sameFile((w.dir / "link.exr").string(), w.scene.string()));
  EXPECT_TRUE(app::sameFile((w.dir / "hard.exr").string(), w.bin.string()));
  EXPECT_FALSE(app::sameFile(w.bin.string(), w.scene.string()));
  // Not created yet: the same directory (by identity) and the same name.
  EXPECT_TRUE(app::sameFile((w.dir / "new.exr").string(), (sub / ".." / "new.exr").string()));
  EXPECT_FALSE(app::sameFile((w.dir / "new.exr").string(), (sub / "new.exr").string()));
  EXPECT_FALSE(app::sameFile((w.dir / "new.exr").string(), (w.dir / "new.png").string()));
}

TEST(OutputPaths, CheckOutputsRefusesInputsOtherOutputsAndWrongExtensions) {
  Workspace w;
  const std::vector<app::NamedPath> inputs = {{"the scene", w.scene.string()},
                                              {"a file of the scene", w.bin.string()}};
  auto exr = [](const fs::path& p) { return app::OutputFile{"--offline", p.string(), ".exr", "OpenEXR"}; };
  auto png = [](const fs::path& p) { return app::OutputFile{"--png", p.string(), ".png", "PNG"}; };
  auto message = [&](const std::vector<app::OutputFile>& outputs) {
    try {
      app::checkOutputs(outputs, inputs);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({exr(w.dir / "out.exr"), png(w.dir / "out.png")}), "accepted");
  EXPECT_EQ(message({exr(w.dir / "OUT.EXR")}), "accepted");  // extensions in any case
  EXPECT_NE(message({png(w.bin)}).find("is a file of the scene"), std::string::npos);
  EXPECT_NE(message({exr(w.scene)}).find("is the scene"), std::string::npos);
  EXPECT_NE(message({exr(w.dir / "a.exr"), png(w.dir / "a.exr")}).find("is also the --offline output"),
            std::string::npos);
  EXPECT_NE(message({exr(w.dir / "x.png")}).find("must end in .exr, not .png"), std::string::npos);
  EXPECT_NE(message({png(w.dir / "x")}).find("must end in .png"), std::string::npos);
  EXPECT_EQ(fs::file_size(w.scene), fs::file_size(test::referencePath("cornell/cornell.gltf")));
}

// osr-vk with an output that is an input, or both outputs one file: exit 2, one line on stderr,
// and every file byte for byte as before (nothing rendered, nothing renamed over it).
TEST(OutputPaths, OsrVkRefusesToOverwriteInputs) {
  Workspace w;
  fs::create_symlink(w.scene, w.dir / "link.exr");
  const std::string before = slurp(w.scene), binBefore = slurp(w.bin), envBefore = slurp(w.env);
  const std::string d = w.dir.string(), scene = w.scene.string();
  const std::pair<std::string, std::string> cases[] = {
      {"--offline " + scene + " " + scene, "is the scene"},
      {"--offline " + d + "/link.exr " + scene, "is the scene"},
      {"--png " + d + "/cornell.bin " + scene, "is a file of the scene"},
      {"--png " + d + "/sky.exr --env " + d + "/sky.exr " + scene, "is the --env map"},
      {"--mode osr --weights " + d + "/model.osrw --offline " + d + "/model.osrw " + scene,
       "is the --weights file"},
      {"--offline " + d + "/out.exr --png " + d + "/sub/../out.exr " + scene,
       "is also the --offline output"},
      {"--offline " + d + "/x.png --png " + d + "/x.exr " + scene, "must end in .exr, not .png"},
  };
  for (const auto& [args, problem] : cases) {
    SCOPED_TRACE(args);
    fs::create_directories(w.dir / "sub");
    test::CliResult r = test::runOsrVk("--width 8 --quiet " + args);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << "one line: " << r.out;
    EXPECT_NE(r.out.find(problem), std::string::npos) << r.out;
  }
  {
    // The scene named relatively, from another directory: the same file.
    const std::string cmd = "cd " + d + "/sub && " + std::string(OSR_BINARY_DIR) +
                            "/osr-vk --mode path --spp 1 --width 8 --quiet --offline ../cornell.gltf " + scene +
                            " >/dev/null 2>&1";
    const int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << cmd;
  }
  EXPECT_EQ(slurp(w.scene), before);
  EXPECT_EQ(slurp(w.bin), binBefore);
  EXPECT_EQ(slurp(w.env), envBefore);
  EXPECT_FALSE(fs::exists(w.dir / "out.exr"));
  EXPECT_FALSE(fs::exists(w.dir / "x.exr"));
}
