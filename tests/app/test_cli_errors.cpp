// The osr-vk executable on bad scene files: exit code 2 and exactly one line on stderr that
// names the file (DESIGN.md "Output"), never a crash. Both executables (osr-vk, osr-bench):
// --help anywhere prints the usage on stdout with exit 0, bad option values are one line and
// exit 2, and a device limit is exit 1.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/vk_test.h"

namespace {

// Files of this process only: the fixed names in gtest's shared TempDir() collided with
// the same suite run at the same time from another checkout or build folder.
std::string tempPrefix() {
  return osr::test::tempDir("cli_errors").string() + "/";
}

struct Outcome {
  int exitCode;
  std::string err;
  std::string out;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Outcome runExe(const std::string& exe, const std::string& args) {
  std::string errFile = tempPrefix() + "osr_cli_stderr.txt";
  std::string outFile = tempPrefix() + "osr_cli_stdout.txt";
  std::string cmd = std::string(OSR_BINARY_DIR) + "/" + exe + " " + args + " >" + outFile + " 2>" + errFile;
  int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), slurp(errFile),
          slurp(outFile)};
}

Outcome runOsr(const std::string& args) { return runExe("osr-vk", args); }

bool placeholderRender(const Outcome& r) {
  return r.err.find("unknown option '--offline'") != std::string::npos;
}

// Runs the render command on `scene`. The full command wants an output (--offline); while the
// render command is still the placeholder, which knows no options, the scene alone is enough.
Outcome renderScene(const std::string& scene, const std::string& options = "") {
  std::string out = tempPrefix() + "osr_cli_test.exr";
  Outcome r = runOsr("--offline '" + out + "' " + options + " '" + scene + "'");
  if (placeholderRender(r) && options.empty()) r = runOsr("'" + scene + "'");
  return r;
}

void expectOneLine(const Outcome& r, const std::string& start, int exitCode = 2) {
  EXPECT_EQ(r.exitCode, exitCode) << r.err;
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
  EXPECT_EQ(r.err.rfind(start, 0), 0u) << r.err;
}

}  // namespace

TEST(CliErrors, BadScenesExitTwoWithOneLine) {
  const char* files[] = {"no_such_file.gltf",
                         "bad_truncated.glb",
                         "bad_json.gltf",
                         "bad_accessor_range.gltf",
                         "bad_buffer_view_range.gltf",
                         "bad_index.gltf",
                         "bad_nan.gltf",
                         "bad_inf.gltf",
                         "bad_missing_texture.gltf",
                         "bad_no_triangles.gltf",
                         "bad_missing_bin.gltf",
                         "bad_sparse_index.gltf"};
  for (const char* name : files) {
    std::string path = osr::test::dataPath(std::string("scene/") + name);
    Outcome r = renderScene(path);
    EXPECT_EQ(r.exitCode, 2) << name << ": " << r.err;
    ASSERT_FALSE(r.err.empty()) << name;
    EXPECT_EQ(r.err.back(), '\n') << name;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << name << ": more than one line: " << r.err;
    EXPECT_EQ(r.err.rfind("osr-vk: " + path + ": ", 0), 0u) << r.err;
  }
}

TEST(CliErrors, UnknownOptionExitsTwo) {
  Outcome r = runOsr("--no-such-option " + osr::test::referencePath("cornell/cornell.gltf"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

// A script saved with CRLF line ends passes its last argument with a '\r': the message quotes
// it as an escape, one line that the terminal does not overwrite from its start.
TEST(CliErrors, ControlCharactersInAnArgumentAreEscaped) {
  Outcome r = runOsr("--spp \"$(printf '4\\r')\" " + osr::test::referencePath("cornell/cornell.gltf"));
  expectOneLine(r, "osr-vk: render: option --spp expects an integer, got '4\\r'");
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
}

// --camera and --env reach the scene code once the render command takes them.
TEST(CliErrors, BadCameraAndEnvironment) {
  std::string cornell = osr::test::referencePath("cornell/cornell.gltf");
  Outcome camera = renderScene(cornell, "--camera nope");
  if (placeholderRender(camera)) GTEST_SKIP() << "render command not built yet";
  expectOneLine(camera, "osr-vk: " + cornell + ": no camera named 'nope'");
  expectOneLine(renderScene(cornell, "--camera 3"),
                "osr-vk: " + cornell + ": camera 3 does not exist");
  std::string env = tempPrefix() + "no_such_env.exr";
  expectOneLine(renderScene(cornell, "--env '" + env + "'"), "osr-vk: " + env + ": file not found");
}

// --help or -h anywhere in a command's arguments, and `osr-vk help [COMMAND]`: that command's
// usage on stdout, nothing on stderr, exit 0, whatever else is on the line.
// The image denoiser switch (docs/denoise.md): a map denoiser's weights, a truncated file,
// an unknown filter, and --network default while no image model is shipped, each refused
// before rendering.
TEST(CliErrors, BadDenoiserExitsTwoWithOneLine) {
  const std::string cornell = osr::test::referencePath("cornell/cornell.gltf");
  const std::string mapModel = osr::test::dataPath("unet_k8.osrw");
  expectOneLine(renderScene(cornell, "--network '" + mapModel + "'"),
                "osr-vk: " + mapModel + ": model of stage 'map_denoiser' (osr_unet_v1), this needs stage "
                "'image_denoiser' (osr_image_unet_v1)");
  const std::string cut = tempPrefix() + "cut.osrw";
  {
    std::ifstream in(osr::test::dataPath("image_unet_k8.osrw"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  expectOneLine(renderScene(cornell, "--network '" + cut + "'"), "osr-vk: " + cut + ": truncated");
  expectOneLine(renderScene(cornell, "--filter bilateral"), "osr-vk: --filter: unknown filter 'bilateral'");
  Outcome shipped = renderScene(cornell, "--network default --spp 1 --mode path --width 8 --height 8");
  if (shipped.exitCode != 0)
    expectOneLine(shipped, "osr-vk: --network default: no image denoiser model shipped");
}

TEST(CliErrors, HelpAnywherePrintsTheUsage) {
  const std::string cornell = osr::test::referencePath("cornell/cornell.gltf");
  const std::pair<std::string, std::string> cases[] = {
      {"--help", "usage: osr-vk [options] scene.gltf"},
      {"-h", "usage: osr-vk [options] scene.gltf"},
      {"help", "usage: osr-vk [options] scene.gltf"},
      {cornell + " --help", "--offline out.exr"},
      {"--spp 4 -h --offline x.exr " + cornell, "--offline out.exr"},
      {"--no-such-option --help", "usage: osr-vk [options] scene.gltf"},
      {"unet --help", "usage: osr-vk unet --weights FILE"},
      {"unet --weights w.osrw -h", "usage: osr-vk unet --weights FILE"},
      {"help unet", "usage: osr-vk unet --weights FILE"},
      {"compare --help", "usage: osr-vk compare TEST.exr REF.exr"},
      {"maps --grid 4 --help", "usage: osr-vk maps scene.gltf"},
      {"help maps", "usage: osr-vk maps scene.gltf"},
      {"compare a.exr --bogus --help", "usage: osr-vk compare TEST.exr REF.exr"},
      {"help compare", "the reference (second)"},
      {"--help", "--mode path|osr|preview  integrator (default path)"},
      {"--help", "--passes N"},
      {"--help", "--env file.exr|.hdr|none"},
      {"--help", "--grid-start R"},
      {"--help", "--network default|none|FILE"},
      {"--help", "(default per mode: path default, osr default, preview none)"},
      {"--help", "(default per mode: path atrous, osr atrous, preview none)"},
      {"--list-devices --help", "usage: osr-vk --list-devices"},
  };
  for (const auto& [args, usage] : cases) {
    Outcome r = runOsr(args);
    EXPECT_EQ(r.exitCode, 0) << args << ": " << r.err;
    EXPECT_EQ(r.err, "") << args;
    EXPECT_NE(r.out.find(usage), std::string::npos) << args << ": " << r.out;
  }
}

// `osr-vk help NAME` with a NAME that is no command is a mistake, not a request for the
// general usage (which it printed, exit 0, as if the typo were an answer).
TEST(CliErrors, HelpForAnUnknownCommandExitsTwo) {
  expectOneLine(runOsr("help mpas"), "osr-vk: help: unknown command 'mpas'");
}

// The same option twice would silently drop one of the values (the output named first was
// never written): refused before any work.
TEST(CliErrors, AnOptionGivenTwiceExitsTwo) {
  const std::string dir = tempPrefix();
  Outcome r = runOsr("--mode preview --offline '" + dir + "twice_a.exr' --offline '" + dir +
                     "twice_b.exr' " + osr::test::referencePath("cornell/cornell.gltf"));
  expectOneLine(r, "osr-vk: render: option --offline given twice");
}

// --exposure shapes the PNG alone and --exr-float the EXR alone: without that file they were
// ignored silently (an EXR "with exposure 2" came out as without).
TEST(CliErrors, OptionsOfAFileNotWrittenExitTwo) {
  const std::string cornell = osr::test::referencePath("cornell/cornell.gltf");
  const std::string dir = tempPrefix();
  expectOneLine(
      runOsr("--mode preview --exposure 2 --offline '" + dir + "exposure.exr' " + cornell),
      "osr-vk: --exposure: sets the exposure of the --png preview");
  expectOneLine(runOsr("--mode preview --exr-float --png '" + dir + "float.png' " + cornell),
                "osr-vk: --exr-float: an option of the --offline EXR");
}

// The viewer's --save-dir must be a folder: it was taken as given and every save (S, the
// panel's buttons) then failed. Refused before the window opens, so no display is needed.
TEST(CliErrors, SaveDirThatIsNoFolderExitsTwo) {
  const std::string cornell = osr::test::referencePath("cornell/cornell.gltf");
  const std::string missing = tempPrefix() + "no_such_folder";
  expectOneLine(runOsr("--save-dir '" + missing + "' " + cornell),
                "osr-vk: --save-dir: " + missing + " is not a folder");
}

// --crop must lie inside the image it is a window of: one line, before any work.
TEST(CliErrors, CropOutsideTheImageExitsTwo) {
  const std::string cornell = osr::test::referencePath("cornell/cornell.gltf");
  const std::string out = tempPrefix() + "osr_cli_crop.exr";
  expectOneLine(runOsr("--width 64 --height 64 --crop 60,0,10,10 --offline '" + out + "' " + cornell),
                "osr-vk: --crop: 60,0,10,10 is not inside the 64x64 image");
  expectOneLine(runOsr("--crop 1,2,3 --offline '" + out + "' " + cornell),
                "osr-vk: --crop: expected X,Y,W,H (the window's corner and size, W and H >= 1)");
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliErrors, VersionIsOneLine) {
  Outcome r = runOsr("--version");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out.rfind("osr-vk ", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << r.out;
  // The build's commit (git describe of the source tree), or "unknown" outside git.
  EXPECT_NE(r.out.find("(commit "), std::string::npos) << r.out;
}

// A film larger than the device can allocate is the device's limit, not bad input: exit 1,
// one line naming the size and the limit. 16384^2 pixels of FilmPixel are 24 GiB, over
// lavapipe's (and most devices') maxMemoryAllocationSize.
TEST(CliErrors, FilmOverTheDeviceLimitExitsOne) {
  std::string out = tempPrefix() + "osr_cli_huge.exr";
  Outcome r = runOsr("--mode preview --spp 1 --quiet --width 16384 --height 16384 --offline '" +
                     out + "' " + osr::test::referencePath("cornell/cornell.gltf"));
  expectOneLine(r, "osr-vk: error: 16384x16384 preview render failed: film: 16384x16384 needs 24576 MiB", 1);
  EXPECT_NE(r.err.find("maxMemoryAllocationSize"), std::string::npos) << r.err;
}

// Messages a person reads: option ranges as numbers they would type, an image renamed .glb,
// camera numbers as the file numbers them.
TEST(CliErrors, MessagesAgreeWithWhatTheUserWrote) {
  const std::string cornell = osr::test::referencePath("cornell/cornell.gltf");
  expectOneLine(runOsr("--time 100000000 --offline x.exr " + cornell),
                "osr-vk: render: option --time must be in [0.001, 10000000], got 100000000");
  expectOneLine(runOsr("--exposure 100 --offline x.exr " + cornell),
                "osr-vk: render: option --exposure must be in [-64, 64], got 100");
  const std::string png = tempPrefix() + "osr_cli_image.glb";
  {
    std::ofstream f(png, std::ios::binary);
    f << "\x89PNG\r\n\x1a\n" << std::string(64, '\0');
  }
  expectOneLine(renderScene(png), "osr-vk: " + png + ": not a glTF or GLB file");
  const std::string cameras = osr::test::dataPath("scene/cameras.gltf");
  // The loader's warning names camera 2 too; the error is the last line.
  Outcome ortho = renderScene(cameras, "--camera 2");
  EXPECT_EQ(ortho.exitCode, 2);
  EXPECT_NE(ortho.err.find("warning: " + cameras + ": camera 2: only perspective"), std::string::npos)
      << ortho.err;
  EXPECT_NE(ortho.err.find("\nosr-vk: " + cameras +
                           ": camera 2 is orthographic, which osr-vk cannot render (usable "
                           "cameras: 0, 1)\n"),
            std::string::npos)
      << ortho.err;
  expectOneLine(runOsr("compare only.exr"),
                "osr-vk: compare: expected two images, TEST.exr REF.exr (the reference second)");
}

TEST(CliErrors, BenchHelpAnywhere) {
  const std::pair<std::string, std::string> cases[] = {
      {"", "usage: osr-bench NAME [options]"},
      {"--help", "usage: osr-bench NAME [options]"},
      {"-h", "usage: osr-bench NAME [options]"},
      {"unet --help", "usage: osr-bench unet [--k"},
      {"unet --help", "--min-seconds S    time each point"},
      {"bvh --help", "usage: osr-bench bvh"},
      {"trace --help", "usage: osr-bench trace"},
      {"osr --help", "--budgets LIST"},
      {"unet --k 8 -h", "usage: osr-bench unet [--k"},
      {"pathtrace --size 8 --help", "usage: osr-bench pathtrace"},
      {"fill --help", "usage: osr-bench fill"},
      {"animation --help", "usage: osr-bench animation"},
      {"osr-error --help", "usage: osr-bench osr-error"},
  };
  for (const auto& [args, usage] : cases) {
    Outcome r = runExe("osr-bench", args);
    EXPECT_EQ(r.exitCode, 0) << args << ": " << r.err;
    EXPECT_EQ(r.err, "") << args;
    EXPECT_NE(r.out.find(usage), std::string::npos) << args << ": " << r.out;
  }
  // With no name: one line per benchmark, each named, and nothing run.
  Outcome list = runExe("osr-bench", "");
  for (const char* name : {"fill", "pathtrace", "bvh", "trace", "unet", "osr"})
    EXPECT_NE(list.out.find(std::string("\n  ") + name + " "), std::string::npos) << name;
  EXPECT_EQ(list.out.find("{\""), std::string::npos) << "ran a benchmark: " << list.out;
}

// Benchmark options go through app::Args: a bad value or an unknown option is one line on
// stderr and exit 2, before any device work.
TEST(CliErrors, BenchBadOptionsExitTwoWithOneLine) {
  const std::pair<std::string, std::string> cases[] = {
      {"unet --min-seconds x", "osr-bench: unet: option --min-seconds expects a number, got 'x'"},
      {"unet --k 16,x", "osr-bench: unet: option --k expects an integer, got 'x'"},
      {"unet --batch 0", "osr-bench: unet: option --batch must be in [1, "},
      {"unet --tile 4", "osr-bench: unet: option --tile takes HxW"},
      {"unet --precision fp8", "osr-bench: unet: --precision takes fp32,fp16"},
      {"unet --bogus", "osr-bench: unet: unknown option '--bogus'"},
      {"unet --chunk", "osr-bench: unet: option --chunk needs a value"},
      {"fill --bogus", "osr-bench: fill: unknown option '--bogus'"},
      {"pathtrace --spp x", "osr-bench: pathtrace: option --spp expects an integer"},
      {"bvh --repeat 0", "osr-bench: bvh: option --repeat must be in [1, 100]"},
      {"trace --bvh-access x", "osr-bench: trace: --bvh-access must be"},
      {"no-such-benchmark", "osr-bench: unknown benchmark 'no-such-benchmark'"},
      {"osr --size x", "osr-bench: osr: option --size expects an integer, got 'x'"},
      {"osr-error --seeds 1", "osr-bench: osr-error: option --seeds must be in [2, 64]"},
      {"osr-error --scene x.gltf",
       "osr-bench: --scene x.gltf: a scene other than cornell or room needs --reference FILE.exr"},
      {"osr-error --reference /nonexistent.exr", "osr-bench: /nonexistent.exr: "},
      {"all --size 8", "osr-bench: all: takes no options"},
      {"--record", "osr-bench: --record: name a benchmark"},
      {"fill --record --record", "osr-bench: --record: given twice"},
  };
  for (const auto& [args, start] : cases) {
    SCOPED_TRACE(args);
    expectOneLine(runExe("osr-bench", args), start);
  }
}

// osr-bench animation refuses a scene it cannot measure and a frame range without a flicker
// pair before it generates a scene or renders a reference.
TEST(CliErrors, BenchAnimationBadInputExitsTwoWithOneLine) {
  const std::string still = osr::test::dataPath("scene/quad.glb");
  const std::pair<std::string, std::string> cases[] = {
      {"animation --frames 5-3", "osr-bench: --frames: '5-3' ends before it starts"},
      {"animation --frames 3", "osr-bench: --frames: the flicker needs at least two frames, got 1"},
      {"animation --frames 0-x", "osr-bench: --frames: '0-x' is not a frame range"},
      {"animation --reference-frames 60",
       "osr-bench: --reference-frames: frame 60 is outside --frames 0-47"},
      {"animation --frames 0-9 --reference-frames 3,5",
       "osr-bench: --reference-frames: the flicker needs two consecutive frames among them"},
      {"animation --frames 0-9 --resume", "osr-bench: --resume: not an option of osr-bench animation"},
      {"animation --scene '" + still + "'", "osr-bench: " + still + ": the scene has no animation"},
  };
  for (const auto& [args, start] : cases) {
    SCOPED_TRACE(args);
    expectOneLine(runExe("osr-bench", args), start);
  }
}
