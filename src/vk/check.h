// One place that turns a failed VkResult into a DeviceError naming the operation.
#pragma once
#include <vulkan/vulkan.h>

#include <string>

namespace osr::vk {

const char* resultName(VkResult result);

// Throws DeviceError("<what>: VK_ERROR_...") unless result is VK_SUCCESS.
void check(VkResult result, const char* what);

}  // namespace osr::vk
