// app::Args, the option reader of every osr-vk command and benchmark: values in both spellings,
// ranges, and the mistakes a person makes on a command line, each an InputError naming the
// option.
#include "app/args.h"

#include <gtest/gtest.h>

#include "common/error.h"

using osr::InputError;
using osr::app::Args;

namespace {

std::string errorOf(Args& a, const std::string& name) {
  try {
    a.value(name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Args, ValuesInBothSpellings) {
  Args a({"--width", "64", "--height=32", "scene.gltf"}, "render");
  EXPECT_EQ(a.integer("--width", 1, 100), 64);
  EXPECT_EQ(a.integer("--height", 1, 100), 32);
  EXPECT_EQ(a.positional(), std::vector<std::string>{"scene.gltf"});
  EXPECT_NO_THROW(a.finish());
}

// `--offline a.exr --offline b.exr` used to write b.exr alone, silently: a second value is
// refused, in either spelling, naming both.
TEST(Args, AnOptionGivenTwiceIsRefused) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--offline", "a.exr", "--offline", "b.exr"},
        std::vector<std::string>{"--offline=a.exr", "--offline", "b.exr"},
        std::vector<std::string>{"--offline", "a.exr", "x.gltf", "--offline=b.exr"}}) {
    Args a(args, "render");
    EXPECT_EQ(errorOf(a, "--offline"), "render: option --offline given twice ('a.exr', 'b.exr')")
        << args[0] << " " << args[1] << " " << args[2];
  }
  Args once({"--offline", "a.exr", "--png", "a.png"}, "render");
  EXPECT_EQ(once.value("--offline"), "a.exr");
}

TEST(Args, MissingAndUnknown) {
  Args a({"--spp"}, "render");
  EXPECT_EQ(errorOf(a, "--spp"), "render: option --spp needs a value");
  Args b({"--spp", "0"}, "render");
  EXPECT_THROW(b.integer("--spp", 1, 10), InputError);
  Args c({"--frobnicate"}, "render");
  EXPECT_THROW(c.finish(), InputError);
}
