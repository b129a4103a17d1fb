// readSpirvComputeInfo against the shaders this build embeds, and planSubgroups' rules
// (docs/subgroups.md).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "common/error.h"
#include "shaders/shader_id.h"
#include "vk/context.h"
#include "vk/spirv_info.h"

namespace osr {
namespace {

const shaders::Module* findModule(const std::string& name) {
  for (size_t i = 0; i < shaders::kModuleCount; ++i) {
    const shaders::Module& m = shaders::module(static_cast<shaders::Id>(i));
    if (name == m.name) return &m;
  }
  return nullptr;
}

vk::SpirvComputeInfo infoOf(const std::string& name, std::vector<vk::SpecConstant> spec = {}) {
  const shaders::Module* m = findModule(name);
  if (!m) throw std::runtime_error("no shader " + name);
  return vk::readSpirvComputeInfo({m->code, m->words}, spec);
}

TEST(SpirvInfo, SubgroupUseIsReadFromCapabilities) {
  EXPECT_TRUE(infoOf("bvh_ploc_count").usesSubgroups);
  EXPECT_TRUE(infoOf("bvh_ploc_local").usesSubgroups);
  EXPECT_TRUE(infoOf("nn_conv").usesSubgroups);
  EXPECT_FALSE(infoOf("util_fill").usesSubgroups);
  EXPECT_FALSE(infoOf("osr_resolve").usesSubgroups);
}

TEST(SpirvInfo, LocalSizeFromLiteralsAndSpecializationConstants) {
  const vk::SpirvComputeInfo fill = infoOf("util_fill");
  EXPECT_EQ(fill.localSize[0], 64u);
  EXPECT_EQ(fill.localSize[1], 1u);
  EXPECT_EQ(fill.localSize[2], 1u);
  // nn_conv's workgroup is a specialization constant (kSpecWorkgroup, constant_id 0).
  const uint32_t defaultSize = infoOf("nn_conv").localSize[0];
  EXPECT_GT(defaultSize, 0u);
  EXPECT_EQ(infoOf("nn_conv", {vk::specUint(0, 24)}).localSize[0], 24u);
}

// Every pass with subgroup operations runs workgroups that hold whole subgroups of any size
// planSubgroups accepts (4 to 64), unless its size is specialized by the host (nn_conv picks a
// multiple of the device's subgroup size).
TEST(SpirvInfo, SubgroupPassesHoldWholeSubgroups) {
  int passes = 0;
  for (size_t i = 0; i < shaders::kModuleCount; ++i) {
    const shaders::Module& m = shaders::module(static_cast<shaders::Id>(i));
    const vk::SpirvComputeInfo info = vk::readSpirvComputeInfo({m.code, m.words});
    if (!info.usesSubgroups || std::string(m.name) == "nn_conv") continue;
    ++passes;
    EXPECT_EQ(info.localSize[0] % 64u, 0u) << m.name << ": workgroup " << info.localSize[0];
  }
  EXPECT_GT(passes, 5);
}

TEST(SpirvInfo, MalformedModulesAreRefused) {
  const uint32_t notSpirv[] = {1, 2, 3, 4, 5};
  EXPECT_THROW(vk::readSpirvComputeInfo(notSpirv), InputError);
  const uint32_t overrun[] = {0x07230203u, 0x10500, 0, 10, 0, (9u << 16) | 17u, 61};
  EXPECT_THROW(vk::readSpirvComputeInfo(overrun), InputError);
}

TEST(PlanSubgroups, AcceptsFixedPowerOfTwoSizesFrom4To64) {
  for (uint32_t s : {4u, 8u, 16u, 32u, 64u}) {
    vk::SubgroupPlan p = vk::planSubgroups("gpu", s, s, s, false, false);
    EXPECT_EQ(p.minSize, s);
    EXPECT_FALSE(p.requireFull);
  }
  for (uint32_t s : {1u, 2u, 12u, 128u})
    EXPECT_THROW(vk::planSubgroups("gpu", s, s, s, true, false), DeviceError) << s;
}

TEST(PlanSubgroups, VaryingSizesNeedFullSubgroups) {
  vk::SubgroupPlan p = vk::planSubgroups("gpu", 32, 8, 32, true, false);
  EXPECT_TRUE(p.requireFull);
  EXPECT_EQ(p.maxSize, 32u);
  try {
    vk::planSubgroups("Some GPU", 32, 8, 32, false, false);
    FAIL() << "no error";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("Some GPU"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("8 to 32"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(vk::planSubgroups("gpu", 8, 8, 8, true, true).requireFull);
  EXPECT_FALSE(vk::planSubgroups("gpu", 8, 8, 8, false, true).requireFull);
}

}  // namespace
}  // namespace osr
