// A minimal reproduction of a heap corruption inside the Khronos validation layer 1.3.239
// (Debian 12's vulkan-validationlayers), independent of osr-vk's code (docs/testing.md).
//
// The layer keeps command buffer debug labels in one map. Its CMD_BUFFER_STATE destructor
// erases the buffer's entry from that map without the map's mutex (fixed upstream in
// 2a430d9d3, "layers: Fix debug label race conditions", first in SDK 1.3.243). The layer's
// queue thread drops the last reference to a submitted command buffer's state after it has
// signalled the submission's fence, so once the application frees that command buffer the
// destructor runs on the queue thread, at the same time as the application's next
// vkCmdBeginDebugUtilsLabelEXT inserts into the same map: a use after free.
//
// Build and run (exit 0: no crash in N rounds; a crash or abort: reproduced):
//   g++ -O2 -std=c++17 tools/repro/vvl_label_race.cpp -o /tmp/vvl_label_race -lvulkan
//   VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation /tmp/vvl_label_race 200000 [nolabel]
// With the argument `nolabel` the same loop records no labels, which never crashes.
#include <vulkan/vulkan.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#define CHECK(x)                                                    \
  do {                                                              \
    VkResult r_ = (x);                                              \
    if (r_ != VK_SUCCESS) {                                         \
      std::fprintf(stderr, "%s failed: %d\n", #x, static_cast<int>(r_)); \
      return 1;                                                     \
    }                                                               \
  } while (0)

int main(int argc, char** argv) {
  const long rounds = argc > 1 ? std::atol(argv[1]) : 100000;
  const bool labels = !(argc > 2 && std::strcmp(argv[2], "nolabel") == 0);

  const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo instanceInfo{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  instanceInfo.pApplicationInfo = &app;
  instanceInfo.enabledExtensionCount = 1;
  instanceInfo.ppEnabledExtensionNames = &extension;
  VkInstance instance;
  CHECK(vkCreateInstance(&instanceInfo, nullptr, &instance));
  auto beginLabel = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkCmdBeginDebugUtilsLabelEXT"));
  auto endLabel = reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkCmdEndDebugUtilsLabelEXT"));

  uint32_t count = 1;
  VkPhysicalDevice physical;
  VkResult enumerated = vkEnumeratePhysicalDevices(instance, &count, &physical);
  if (enumerated != VK_SUCCESS && enumerated != VK_INCOMPLETE) return 1;
  float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queueInfo.queueFamilyIndex = 0;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;
  VkDeviceCreateInfo deviceInfo{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  deviceInfo.queueCreateInfoCount = 1;
  deviceInfo.pQueueCreateInfos = &queueInfo;
  VkDevice device;
  CHECK(vkCreateDevice(physical, &deviceInfo, nullptr, &device));
  VkQueue queue;
  vkGetDeviceQueue(device, 0, 0, &queue);
  VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  VkCommandPool pool;
  CHECK(vkCreateCommandPool(device, &poolInfo, nullptr, &pool));

  // The pattern of a one-shot submission helper: allocate, record, submit, wait, free.
  for (long i = 0; i < rounds; ++i) {
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VkCommandBuffer cmd;
    CHECK(vkAllocateCommandBuffers(device, &alloc, &cmd));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    CHECK(vkBeginCommandBuffer(cmd, &begin));
    if (labels) {
      VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
      label.pLabelName = "a pass";
      beginLabel(cmd, &label);
      endLabel(cmd);
    }
    CHECK(vkEndCommandBuffer(cmd));
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    CHECK(vkCreateFence(device, &fenceInfo, nullptr, &fence));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    CHECK(vkQueueSubmit(queue, 1, &submit, fence));
    CHECK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
    vkDestroyFence(device, fence, nullptr);
    vkFreeCommandBuffers(device, pool, 1, &cmd);
  }
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
  std::printf("%ld rounds, labels %s: no crash\n", rounds, labels ? "on" : "off");
  return 0;
}
