// Whether command buffer debug labels are safe to record under the Khronos validation layer of
// a spec version (0: no layer). Before 1.3.243 the layer's queue thread erases a freed command
// buffer's labels without a lock while the next vkCmdBeginDebugUtilsLabelEXT inserts into the
// same map: heap corruption (docs/testing.md, tools/repro/vvl_label_race.cpp). Context records
// no labels then; object names stay.
#pragma once
#include <cstdint>

namespace osr::vk {

bool commandLabelsSafe(uint32_t validationLayerSpecVersion);

}  // namespace osr::vk
