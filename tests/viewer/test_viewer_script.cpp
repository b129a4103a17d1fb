// --viewer-script parsing: every command with its arguments, comments and blank lines, and one
// line naming FILE:LINE for each kind of mistake.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "common/test_paths.h"
#include "viewer/viewer_script.h"

using namespace osr;

namespace {
std::string write(const std::string& text) {
  const std::string path = (test::tempDir("viewer_script") / "s.txt").string();
  std::ofstream(path) << text;
  return path;
}
std::string errorOf(const std::string& text) {
  try {
    viewer::readViewerScript(write(text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(ViewerScript, ReadsEveryCommand) {
  const auto cmds = viewer::readViewerScript(
      write("# a demo\n"
            "at 1.5\n\n"
            "wait 0.25   # trailing comment\n"
            "wait-units 4\nwait-done\nkey space\norbit 10 -5\npan 0.1 0\nzoom 0.8\n"
            "fly 0.1 0 -0.2\ncamera 0\nreset\nresize 640 480\nscreenshot out.png\nstats\nquit\n"
            "wait-image\n"));
  ASSERT_EQ(cmds.size(), 16u);
  EXPECT_EQ(cmds[0].name, "at");
  EXPECT_EQ(cmds[0].numbers, std::vector<double>{1.5});
  EXPECT_EQ(cmds[0].line, 2);
  EXPECT_EQ(cmds[1].line, 4);
  EXPECT_EQ(cmds[4].text, "space");
  EXPECT_EQ(cmds[5].numbers, (std::vector<double>{10, -5}));
  EXPECT_EQ(cmds[8].numbers, (std::vector<double>{0.1, 0, -0.2}));
  EXPECT_EQ(cmds[11].numbers, (std::vector<double>{640, 480}));
  EXPECT_EQ(cmds[12].text, "out.png");
  EXPECT_EQ(cmds[14].name, "quit");
  EXPECT_EQ(cmds[15].name, "wait-image");
  EXPECT_TRUE(cmds[15].numbers.empty());
}

TEST(ViewerScript, MistakesNameTheLine) {
  EXPECT_NE(errorOf("wait 1\njump 3\n").find("s.txt:2: unknown command 'jump'"), std::string::npos);
  EXPECT_NE(errorOf("orbit 10\n").find("s.txt:1: orbit needs 2 number(s)"), std::string::npos);
  EXPECT_NE(errorOf("zoom x\n").find("'x' is not a number"), std::string::npos);
  EXPECT_NE(errorOf("zoom 0\n").find("factor > 0"), std::string::npos);
  EXPECT_NE(errorOf("key q\n").find("unknown key 'q'"), std::string::npos);
  EXPECT_NE(errorOf("wait -1\n").find("time >= 0"), std::string::npos);
  EXPECT_NE(errorOf("resize 10 10\n").find("[64, 8192]"), std::string::npos);
  EXPECT_NE(errorOf("camera 1.5\n").find("whole number"), std::string::npos);
  EXPECT_NE(errorOf("quit now\n").find("unexpected 'now'"), std::string::npos);
  EXPECT_NE(errorOf("screenshot\n").find("needs an argument"), std::string::npos);
  EXPECT_THROW(viewer::readViewerScript("/nonexistent/s.txt"), InputError);
}

// `mode NAME` switches the integrator; the names are the viewer's (ViewerConfig::modes).
TEST(ViewerScript, ModeNamesAreTheViewers) {
  const std::vector<std::string> modes = {"path", "preview", "osr"};
  const auto cmds = viewer::readViewerScript(write("mode path\nmode osr\n"), modes);
  ASSERT_EQ(cmds.size(), 2u);
  EXPECT_EQ(cmds[0].name, "mode");
  EXPECT_EQ(cmds[1].text, "osr");
  try {
    viewer::readViewerScript(write("wait 1\nmode fast\n"), modes);
    ADD_FAILURE() << "an unknown mode was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.txt:2: unknown mode 'fast' (path, preview, osr)"),
              std::string::npos)
        << e.what();
  }
}

// Found by tests/fuzz/fuzz_viewer_script.cpp (tests/fuzz/regressions/viewer_script): numbers the
// viewer would turn into an infinite float or an out-of-range integer, and a NUL that hid the
// rest of a word.
TEST(ViewerScript, NumbersTheViewerCannotUseAreRefused) {
  EXPECT_NE(errorOf("fly 1e50 0 0\n").find("s.txt:1: fly: 1e50 is out of range"), std::string::npos);
  EXPECT_NE(errorOf("camera 1e12\n").find("out of range"), std::string::npos);
  EXPECT_NE(errorOf("zoom 1e-300\n").find("factor > 0"), std::string::npos);
  EXPECT_NE(errorOf(std::string("resize 640 480\0ens0\n", 20)).find("is not a number"),
            std::string::npos);
  EXPECT_EQ(viewer::parseViewerScript("orbit -1e9 1e9\n", "s.txt").at(0).numbers[1], 1e9);
}
