#include "vk/check.h"

#include "common/error.h"

namespace osr::vk {

const char* resultName(VkResult result) {
  switch (result) {
#define OSR_CASE(x) \
  case x:           \
    return #x;
    OSR_CASE(VK_SUCCESS)
    OSR_CASE(VK_NOT_READY)
    OSR_CASE(VK_TIMEOUT)
    OSR_CASE(VK_INCOMPLETE)
    OSR_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    OSR_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    OSR_CASE(VK_ERROR_INITIALIZATION_FAILED)
    OSR_CASE(VK_ERROR_DEVICE_LOST)
    OSR_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    OSR_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    OSR_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    OSR_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    OSR_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    OSR_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    OSR_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    OSR_CASE(VK_ERROR_FRAGMENTED_POOL)
    OSR_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    OSR_CASE(VK_ERROR_SURFACE_LOST_KHR)
    OSR_CASE(VK_ERROR_OUT_OF_DATE_KHR)
    OSR_CASE(VK_SUBOPTIMAL_KHR)
#undef OSR_CASE
    default:
      return "VK_ERROR_UNKNOWN";
  }
}

void check(VkResult result, const char* what) {
  if (result == VK_SUCCESS) return;
  throw DeviceError(std::string(what) + ": " + resultName(result) + " (" +
                    std::to_string(static_cast<int>(result)) + ")");
}

}  // namespace osr::vk
