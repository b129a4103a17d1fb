// Animation renders, `osr-vk --frames A-B [--fps N] [--resume]`: frame ranges and file names,
// a camera-path shot killed mid-way and resumed (the same frames bit for bit as a shot run
// through), OSR's map cache carried across frames that move an object, and bad input (one
// line, exit 2).
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "app/args.h"
#include "app/cli_runner.h"
#include "app/frames.h"
#include "common/error.h"
#include "common/test_paths.h"
#include "image/image_io.h"
#include "image/image_metrics.h"

extern char** environ;

using namespace osr;
namespace fs = std::filesystem;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::optional<app::FrameOptions> frames(std::vector<std::string> args) {
  app::Args a(std::move(args), "render");
  auto f = app::readFrameOptions(a);
  a.finish();
  return f;
}

void expectRefused(const std::vector<std::string>& args, const std::string& part) {
  try {
    frames(args);
    ADD_FAILURE() << "accepted; expected an InputError containing '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// One line on stderr containing `part`, exit 2.
void expectOneLineError(const std::string& args, const std::string& part) {
  test::CliResult r = test::runOsrVk(args);
  EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
  EXPECT_NE(r.out.find(part), std::string::npos) << args << "\n" << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << "\n" << r.out;
}

const std::string kCameraPath = test::dataPath("scene/camera_path.gltf");
const std::string kShotOptions = "--mode path --spp 8 --width 48 --height 48 --frames 0-3 ";

std::string osrVk() {
  const char* env = std::getenv("OSR_BINARY_DIR");
  return std::string(env ? env : OSR_BINARY_DIR) + "/osr-vk";
}

}  // namespace

TEST(Frames, RangesAndRates) {
  auto f = frames({"--frames", "3-10", "--fps", "30"});
  ASSERT_TRUE(f);
  EXPECT_EQ(f->first, 3);
  EXPECT_EQ(f->last, 10);
  EXPECT_EQ(f->count(), 8);
  EXPECT_DOUBLE_EQ(f->timeS(15), 0.5);
  EXPECT_FALSE(f->resume);
  f = frames({"--frames", "7", "--resume"});
  ASSERT_TRUE(f);
  EXPECT_EQ(f->count(), 1);
  EXPECT_DOUBLE_EQ(f->timeS(12), 0.5);  // 24 frames per second by default
  EXPECT_TRUE(f->resume);
  EXPECT_FALSE(frames({}));
}

TEST(Frames, BadRangesAndRatesAreRefused) {
  expectRefused({"--frames", "5-2"}, "ends before it starts");
  expectRefused({"--frames", "a-b"}, "is not a frame range");
  expectRefused({"--frames", "-3"}, "is not a frame range");
  expectRefused({"--frames", "1-"}, "is not a frame range");
  expectRefused({"--frames", "1-2-3"}, "is not a frame range");
  expectRefused({"--frames", "1234567"}, "is not a frame range");
  expectRefused({"--frames", "0-3", "--fps", "0"}, "--fps: must be above 0");
  expectRefused({"--frames", "0-3", "--fps", "-24"}, "--fps: must be above 0");
  expectRefused({"--fps", "24"}, "an option of --frames");
  expectRefused({"--resume"}, "an option of --frames");
}

TEST(Frames, FileNamesNumberTheLastRunOfHashes) {
  EXPECT_EQ(app::framePath("shot_####.exr", 12), "shot_0012.exr");
  EXPECT_EQ(app::framePath("out/#_##.png", 7), "out/#_07.png");
  EXPECT_EQ(app::framePath("s#.exr", 1234), "s1234.exr");  // wider than the field
  EXPECT_NO_THROW(app::checkFrameField("--offline", "a/shot_#.exr"));
  EXPECT_THROW(app::checkFrameField("--offline", "shot.exr"), InputError);
  EXPECT_THROW(app::checkFrameField("--png", "dir#/shot.png"), InputError);  // not in the name
}

TEST(Frames, OnlyWholeImagesAreComplete) {
  fs::path d = test::tempDir("frames_complete");
  const std::string exr = (d / "a.exr").string(), png = (d / "a.png").string();
  image::LayeredImage img;
  img.width = 4;
  img.height = 3;
  img.layers.push_back({"", {"R", "G", "B"}, std::vector<float>(4 * 3 * 3, 0.5f)});
  image::writeExr(exr, img, image::ExrPixelType::Half);
  image::writePng(png, {4, 3, std::vector<float>(4 * 3 * 3, 0.5f)}, 0.0);
  EXPECT_TRUE(app::frameComplete({exr, png}));
  EXPECT_FALSE(app::frameComplete({exr, (d / "missing.png").string()}));
  // Cut short, as a killed writer without the rename would leave it.
  const std::string bytes = slurp(exr);
  std::ofstream((d / "cut.exr").string(), std::ios::binary).write(bytes.data(), bytes.size() - 8);
  EXPECT_FALSE(app::frameComplete({(d / "cut.exr").string()}));
  fs::remove_all(d);
}

// The whole shot at once, then the same shot killed (SIGKILL) once its first frame is written
// and rerun with --resume: the frames written before the kill are skipped, not rendered again,
// and every frame equals the uninterrupted shot's byte for byte. Temporal reuse is on (the
// default): the resumed run continues from the history the killed one left beside the frames,
// and a complete shot leaves no history behind.
TEST(Frames, KilledShotResumesToTheSameFrames) {
  fs::path d = test::tempDir("frames_resume");
  fs::create_directories(d / "whole");
  fs::create_directories(d / "killed");
  test::CliResult whole = test::runOsrVk(kShotOptions + "--offline " +
                                         (d / "whole/shot_####.exr").string() + " " + kCameraPath);
  ASSERT_EQ(whole.code, 0) << whole.out;
  for (int f = 0; f < 4; ++f)
    EXPECT_NE(whole.out.find("osr-vk: frame " + std::to_string(f + 1) + "/4"), std::string::npos)
        << whole.out;
  // The camera moves: no two frames alike.
  EXPECT_NE(slurp((d / "whole/shot_0000.exr").string()), slurp((d / "whole/shot_0003.exr").string()));

  const std::string killedPattern = (d / "killed/shot_####.exr").string();
  const std::string first = app::framePath(killedPattern, 0);
  std::vector<std::string> argv = {osrVk(), "--quiet"};
  for (const char* a : {"--mode", "path", "--spp", "8", "--width", "48", "--height", "48",
                        "--frames", "0-3", "--offline"})
    argv.push_back(a);
  argv.push_back(killedPattern);
  argv.push_back(kCameraPath);
  std::vector<char*> cargv;
  for (std::string& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  pid_t pid;
  ASSERT_EQ(posix_spawn(&pid, cargv[0], nullptr, nullptr, cargv.data(), environ), 0);
  const auto start = std::chrono::steady_clock::now();
  while (!fs::exists(first) && std::chrono::steady_clock::now() - start < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(fs::exists(first));
  int written = 0;
  for (int f = 0; f < 4; ++f) written += fs::exists(app::framePath(killedPattern, f));
  // The kill must land mid-shot for the test to mean anything.
  ASSERT_TRUE(WIFSIGNALED(status)) << "the shot ended before the kill";
  ASSERT_LT(written, 4) << "every frame was written before the kill";
  const auto firstWritten = fs::last_write_time(first);

  test::CliResult resumed = test::runOsrVk(kShotOptions + "--resume --offline " + killedPattern +
                                           " " + kCameraPath);
  ASSERT_EQ(resumed.code, 0) << resumed.out;
  size_t skipped = 0;
  for (size_t at = 0; (at = resumed.out.find("complete, skipped (--resume)", at)) != std::string::npos; ++at)
    ++skipped;
  EXPECT_GE(skipped, 1u) << resumed.out;
  EXPECT_LE(skipped, size_t(written)) << resumed.out;  // a cut frame is no frame
  EXPECT_EQ(fs::last_write_time(first), firstWritten);
  EXPECT_EQ(resumed.out.find("is not the history"), std::string::npos) << resumed.out;
  EXPECT_FALSE(fs::exists(d / "killed/.shot_####.exr.history0"));
  EXPECT_FALSE(fs::exists(d / "killed/.shot_####.exr.history1"));
  for (int f = 0; f < 4; ++f) {
    const std::string a = app::framePath((d / "whole/shot_####.exr").string(), f);
    const std::string b = app::framePath(killedPattern, f);
    // Pixels, not bytes: the header records each run's own seconds.
    EXPECT_TRUE(image::readExrRgb(a).rgb == image::readExrRgb(b).rgb)
        << "frame " << f << " differs: " << a << " vs " << b;
  }
  // The frames, and at most the killed run's one temporary file (named after its pid): the
  // resumed run leaves none of its own.
  int others = 0;
  for (const auto& e : fs::directory_iterator(d / "killed")) {
    const std::string name = e.path().filename().string();
    if (name.size() == 13 && name.rfind("shot_", 0) == 0) continue;  // shot_NNNN.exr
    EXPECT_NE(name.find(".tmp" + std::to_string(pid)), std::string::npos) << name;
    ++others;
  }
  EXPECT_LE(others, 1);
  fs::remove_all(d);
}

// A shot whose object moves every frame (moving_object.gltf, frames 0-2 at 24 frames/s) keeps
// one OSR integrator and its map cache: frame 2 of the shot depends on the frames before it,
// so it differs from frame 2 rendered alone. Without the cache (--map-cache 0) nothing else is
// carried (nor with --temporal-reuse 0 the frames' films): frame 2 of the shot equals frame 2
// alone bit for bit.
TEST(Frames, OsrCarriesItsMapCacheAcrossFramesThatMoveAnObject) {
  fs::path d = test::tempDir("frames_moving");
  const std::string scene = test::dataPath("scene/moving_object.gltf");
  auto frame2 = [&](const std::string& name, const std::string& frames, const std::string& extra) {
    const std::string pattern = (d / (name + "_#.exr")).string();
    // A grid of 8 x 8 maps: at 16-pixel spacing the maps' cells would reach the whole room
    // from the cube, and every map would be invalidated.
    test::CliResult r = test::runOsrVk(
        "--quiet --mode osr --passes 2 --width 64 --height 64 --grid-start 8 --grid-min 8 " +
        extra + " --frames " + frames + " --offline " + pattern + " " + scene);
    EXPECT_EQ(r.code, 0) << name << "\n" << r.out;
    return image::readExrRgb(app::framePath(pattern, 2)).rgb;
  };
  EXPECT_NE(frame2("shot", "0-2", ""), frame2("alone", "2", ""));
  const std::string nothingCarried = "--map-cache 0 --temporal-reuse 0";
  EXPECT_EQ(frame2("shot0", "0-2", nothingCarried), frame2("alone0", "2", nothingCarried));
  fs::remove_all(d);
}

// The path tracer keeps its integrator across such frames too (PathIntegrator::rebind) and,
// without temporal reuse, carries nothing from frame to frame: frame 2 of the shot equals
// frame 2 alone bit for bit.
TEST(Frames, PathTracingRebindsAcrossFramesThatMoveAnObject) {
  fs::path d = test::tempDir("frames_moving_path");
  const std::string scene = test::dataPath("scene/moving_object.gltf");
  auto frame2 = [&](const std::string& name, const std::string& frames) {
    const std::string pattern = (d / (name + "_#.exr")).string();
    test::CliResult r = test::runOsrVk("--quiet --mode path --spp 4 --width 48 --height 48 "
                                       "--temporal-reuse 0 --frames " +
                                       frames + " --offline " + pattern + " " + scene);
    EXPECT_EQ(r.code, 0) << name << "\n" << r.out;
    return image::readExrRgb(app::framePath(pattern, 2)).rgb;
  };
  const std::vector<float> shot = frame2("shot", "0-2"), alone = frame2("alone", "2");
  EXPECT_EQ(shot, alone);
  // The object moved: frame 0 is another image.
  EXPECT_NE(image::readExrRgb(app::framePath((d / "shot_#.exr").string(), 0)).rgb, alone);
  fs::remove_all(d);
}

// Temporal reuse on a real shot: the last of 6 frames of the camera path at 8 spp, raw, is
// closer to a 512-spp render of it with reuse than without (it gathered about 4 frames'
// samples: 6 dB in PSNR at best; the tone-mapped error, since at 8 spp a few lamp-edge pixels
// that caught the lamp or missed it make most of a relMSE), and its mean is the same.
TEST(Frames, TemporalReuseLowersTheErrorOfACameraPath) {
  fs::path d = test::tempDir("frames_reuse");
  const std::string raw = "--quiet --mode path --network none --filter none --width 48 --height 48 ";
  auto last = [&](const std::string& name, const std::string& extra) {
    const std::string pattern = (d / (name + "_#.exr")).string();
    test::CliResult r = test::runOsrVk(raw + extra + " --offline " + pattern + " " + kCameraPath);
    EXPECT_EQ(r.code, 0) << name << "\n" << r.out;
    return image::readExrRgb(app::framePath(pattern, 5));
  };
  const image::RgbImage reference = last("ref", "--spp 512 --seed 99 --frames 5 --temporal-reuse 0");
  const image::ImageMetrics reused = image::compareImages(last("reuse", "--spp 8 --frames 0-5"), reference);
  const image::ImageMetrics alone =
      image::compareImages(last("alone", "--spp 8 --frames 0-5 --temporal-reuse 0"), reference);
  EXPECT_GT(reused.psnr, alone.psnr + 2.0) << reused.psnr << " dB against " << alone.psnr;
  EXPECT_NEAR(reused.lumRatio, 1.0, 0.05);
  fs::remove_all(d);
}

TEST(Frames, BadShotsAreOneLineExitTwo) {
  fs::path d = test::tempDir("frames_errors");
  const std::string pattern = (d / "shot_####.exr").string();
  const std::string cornell = test::referencePath("cornell/cornell.gltf");
  expectOneLineError("--frames 0-3 --offline " + pattern + " " + cornell, "has no animation");
  expectOneLineError("--frames 0-3 --offline " + (d / "shot.exr").string() + " " + kCameraPath,
                     "frame field");
  expectOneLineError("--frames 0-3 --offline " + pattern + " --png " + (d / "shot.png").string() +
                         " " + kCameraPath,
                     "frame field");
  expectOneLineError("--frames 3-0 --offline " + pattern + " " + kCameraPath, "ends before");
  expectOneLineError("--frames 0-x --offline " + pattern + " " + kCameraPath, "not a frame range");
  expectOneLineError("--frames 0-3 --fps 0 --offline " + pattern + " " + kCameraPath,
                     "--fps: must be above 0");
  expectOneLineError("--resume --offline " + pattern + " " + kCameraPath, "an option of --frames");
  expectOneLineError("--temporal-reuse 2 --offline " + pattern + " " + kCameraPath,
                     "an option of --frames");
  expectOneLineError("--frames 0-3 --temporal-reuse -1 --offline " + pattern + " " + kCameraPath,
                     "--temporal-reuse");
  expectOneLineError("--frames 0-3 --temporal-reuse 65 --offline " + pattern + " " + kCameraPath,
                     "--temporal-reuse");
  expectOneLineError("--frames 0-3 " + kCameraPath, "--frames");
  EXPECT_TRUE(fs::is_empty(d));
  fs::remove_all(d);
}
