// main() for every device test executable: runs gtest and turns any validation message reported
// while a test ran into a failure of that test.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "vk_test.h"

namespace osr::test {

namespace {
std::unique_ptr<vk::Context> gContext;
}

vk::Context& context() {
  if (!gContext) {
    vk::ContextOptions options;
    options.validation = true;
    // OSR_TEST_FULL_SUBGROUPS=1: every subgroup pipeline asks for full subgroups, as on a
    // device whose subgroup size varies (CI runs the device suites so, docs/subgroups.md).
    const char* full = std::getenv("OSR_TEST_FULL_SUBGROUPS");
    options.testRequireFullSubgroups = full && std::string(full) == "1";
    gContext = std::make_unique<vk::Context>(options);
  }
  return *gContext;
}

namespace {
class ValidationListener : public ::testing::EmptyTestEventListener {
  uint32_t before_ = 0;
  void OnTestStart(const ::testing::TestInfo&) override {
    before_ = gContext ? gContext->validationMessages() : 0;
  }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    uint32_t after = gContext ? gContext->validationMessages() : 0;
    if (after != before_)
      ADD_FAILURE() << info.name() << ": " << (after - before_)
                    << " Vulkan validation message(s), see stderr";
  }
};
}  // namespace

}  // namespace osr::test

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::UnitTest::GetInstance()->listeners().Append(new osr::test::ValidationListener);
  int result = RUN_ALL_TESTS();
  // Belt and braces: a validation message anywhere fails the executable.
  if (osr::test::gContext && osr::test::gContext->validationMessages() > 0) {
    std::fprintf(stderr, "%u Vulkan validation message(s) during the run\n",
                 osr::test::gContext->validationMessages());
    result = 1;
  }
  osr::test::gContext.reset();
  return result;
}
