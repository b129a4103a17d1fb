// What a compute shader's SPIR-V says about its subgroup use and workgroup size, read from
// the module itself so that every pass is covered without a hand-kept list
// (docs/subgroups.md: the pipeline asks for full subgroups where the device could split them).
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>

#include "vk/pipeline.h"

namespace osr::vk {

struct SpirvComputeInfo {
  bool usesSubgroups = false;      // declares a GroupNonUniform* or SubgroupBallot/Vote capability
  uint32_t localSize[3] = {1, 1, 1};  // with the given specialization constants applied
};

// Reads the capabilities, the LocalSize execution mode, the WorkgroupSize built-in and the
// specialization constants of a SPIR-V module; throws InputError on a malformed module.
SpirvComputeInfo readSpirvComputeInfo(std::span<const uint32_t> words,
                                      std::span<const SpecConstant> spec = {});

}  // namespace osr::vk
