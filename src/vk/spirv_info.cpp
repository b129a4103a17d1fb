#include "vk/spirv_info.h"

#include <string>
#include <unordered_map>

#include "common/error.h"

namespace osr::vk {
namespace {
// SPIR-V 1.5 specification, section 3 (opcodes, enumerants) and 2.3 (physical layout).
constexpr uint32_t kMagic = 0x07230203u;
constexpr uint32_t kOpExecutionMode = 16, kOpCapability = 17, kOpConstant = 43,
                   kOpConstantComposite = 44, kOpSpecConstant = 50,
                   kOpSpecConstantComposite = 51, kOpDecorate = 71, kOpExecutionModeId = 331;
constexpr uint32_t kModeLocalSize = 17, kModeLocalSizeId = 38;
constexpr uint32_t kDecorationSpecId = 1, kDecorationBuiltIn = 11, kBuiltInWorkgroupSize = 25;

bool isSubgroupCapability(uint32_t c) {
  // GroupNonUniform (61) through GroupNonUniformQuad (68); SubgroupBallotKHR, SubgroupVoteKHR.
  return (c >= 61 && c <= 68) || c == 4423 || c == 4431;
}
}  // namespace

SpirvComputeInfo readSpirvComputeInfo(std::span<const uint32_t> words,
                                      std::span<const SpecConstant> spec) {
  if (words.size() < 5 || words[0] != kMagic) throw InputError("spirv: not a SPIR-V module");
  SpirvComputeInfo info;
  std::unordered_map<uint32_t, uint32_t> specIdOf;    // result id -> SpecId
  std::unordered_map<uint32_t, uint32_t> constantOf;  // result id -> 32-bit literal
  uint32_t workgroupSizeId = 0, compositeIds[3] = {0, 0, 0};
  bool haveComposite = false;
  uint32_t localSizeIds[3] = {0, 0, 0};
  bool haveLocalSizeIds = false;
  for (size_t at = 5; at < words.size();) {
    const uint32_t count = words[at] >> 16, op = words[at] & 0xffffu;
    if (count == 0 || at + count > words.size())
      throw InputError("spirv: instruction at word " + std::to_string(at) + " overruns the module");
    const uint32_t* w = &words[at];
    if (op == kOpCapability && count >= 2 && isSubgroupCapability(w[1])) info.usesSubgroups = true;
    if (op == kOpExecutionMode && count >= 6 && w[2] == kModeLocalSize)
      for (int i = 0; i < 3; ++i) info.localSize[i] = w[3 + i];
    if (op == kOpExecutionModeId && count >= 6 && w[2] == kModeLocalSizeId) {
      for (int i = 0; i < 3; ++i) localSizeIds[i] = w[3 + i];
      haveLocalSizeIds = true;
    }
    if (op == kOpDecorate && count >= 4 && w[2] == kDecorationSpecId) specIdOf[w[1]] = w[3];
    if (op == kOpDecorate && count >= 4 && w[2] == kDecorationBuiltIn &&
        w[3] == kBuiltInWorkgroupSize)
      workgroupSizeId = w[1];
    if ((op == kOpConstant || op == kOpSpecConstant) && count >= 4) constantOf[w[2]] = w[3];
    if ((op == kOpConstantComposite || op == kOpSpecConstantComposite) && count >= 6 &&
        w[2] == workgroupSizeId && workgroupSizeId != 0) {
      for (int i = 0; i < 3; ++i) compositeIds[i] = w[3 + i];
      haveComposite = true;
    }
    at += count;
  }
  auto value = [&](uint32_t id) {
    auto s = specIdOf.find(id);
    if (s != specIdOf.end())
      for (const SpecConstant& c : spec)
        if (c.id == s->second) return c.bits;
    auto c = constantOf.find(id);
    if (c == constantOf.end()) throw InputError("spirv: workgroup size is not a constant");
    return c->second;
  };
  // The WorkgroupSize built-in overrides the execution mode (SPIR-V 2.16.2).
  if (haveComposite)
    for (int i = 0; i < 3; ++i) info.localSize[i] = value(compositeIds[i]);
  else if (haveLocalSizeIds)
    for (int i = 0; i < 3; ++i) info.localSize[i] = value(localSizeIds[i]);
  return info;
}

}  // namespace osr::vk
