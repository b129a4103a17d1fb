// The Vulkan instance, the chosen physical device, its one compute queue and the capabilities
// every pass reads. Created once per process (or test) and passed by reference; no globals.
#pragma once
#include <vulkan/vulkan.h>

#include <atomic>
#include <functional>
#include <string>
#include <vector>

namespace osr::vk {

struct ContextOptions {
  // Khronos validation layer; also switched on by the environment variable OSR_VALIDATION=1.
  bool validation = false;
  // "" picks discrete GPU, then integrated, then virtual, then CPU; a number is an index into
  // listDevices(); anything else is a case-insensitive substring of the device name.
  std::string device;
  // Print the chosen device and its capabilities on stderr.
  bool verbose = false;
  // Presentation (the viewer): instance extensions the window system needs (from
  // glfwGetRequiredInstanceExtensions) and VK_KHR_swapchain on the device. Empty and false for
  // offline work, so a headless machine never needs a window system.
  std::vector<std::string> instanceExtensions;
  bool swapchain = false;
  // Tests only: when > 0, the device is treated as allowing no allocation larger than this
  // (caps().maxMemoryAllocationSize is lowered to it), so refusals of scenes too large for the
  // device can be tested on small data.
  uint64_t testMaxAllocationBytes = 0;
  // Tests only: ask for full subgroups (VK_EXT_subgroup_size_control) even on a device whose
  // subgroup size does not vary, so that path runs on lavapipe too.
  bool testRequireFullSubgroups = false;
};

struct DeviceInfo {
  uint32_t index = 0;
  std::string name;
  std::string type;  // "discrete", "integrated", "virtual", "cpu", "other"
  uint32_t apiVersion = 0;
};

// Properties chosen once at creation that kernels specialise on.
struct Capabilities {
  std::string deviceName;
  VkPhysicalDeviceType deviceType = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t subgroupSize = 1;
  // The range a pipeline's subgroups may take (VK_EXT_subgroup_size_control; both equal to
  // subgroupSize without it).
  uint32_t minSubgroupSize = 1;
  uint32_t maxSubgroupSize = 1;
  // Pipelines that use subgroup operations are created with REQUIRE_FULL_SUBGROUPS: set where
  // the size may vary (docs/subgroups.md), so that no subgroup is ever partly filled.
  bool requireFullSubgroups = false;
  // Compute shaders may use subgroupShuffle* (GL_KHR_shader_subgroup_shuffle and _relative),
  // with votes and ballots.
  bool subgroupShuffle = false;
  uint64_t maxStorageBufferRange = 0;
  uint64_t maxMemoryAllocationSize = 0;  // largest single allocation (Vulkan 1.1)
  uint32_t maxTexelBufferElements = 0;
  uint32_t maxComputeWorkGroupCount[3] = {};
  uint32_t maxPushConstantsSize = 0;
  float timestampPeriodNs = 1.0f;
  bool timestamps = false;
  bool shaderFloat16 = false;     // fp16 arithmetic in shaders
  bool storageBuffer16Bit = false;  // fp16/int16 loads and stores in storage buffers
  bool shaderInt64 = false;
  // Shaders read through buffer device addresses (GL_EXT_buffer_reference): arrays that pass
  // maxStorageBufferRange, up to one allocation. Every Buffer is addressable when true.
  bool bufferDeviceAddress = false;
  bool unifiedMemory = false;  // device-local memory is also host-visible (lavapipe, iGPUs)
  bool isCpu() const { return deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
};

std::vector<DeviceInfo> listDevices();

// How osr-vk runs a device's subgroups (docs/subgroups.md). Its subgroup passes need whole
// subgroups of consecutive invocations, of one power-of-two size from 4 to 64 (workgroups of
// 64 hold whole subgroups): a device outside that range, or whose size may vary per pipeline
// but cannot be asked for full subgroups, is refused with a DeviceError naming it.
struct SubgroupPlan {
  uint32_t minSize = 1;
  uint32_t maxSize = 1;
  bool requireFull = false;  // create subgroup pipelines with REQUIRE_FULL_SUBGROUPS
};
SubgroupPlan planSubgroups(const std::string& deviceName, uint32_t size, uint32_t minSize,
                           uint32_t maxSize, bool canRequireFull, bool forceRequireFull);

class Context {
 public:
  explicit Context(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queueFamily_; }
  const Capabilities& caps() const { return caps_; }
  bool validationEnabled() const { return validation_; }

  // Number of validation warnings and errors reported so far (tests require zero).
  uint32_t validationMessages() const { return validationMessages_.load(); }

  // Memory type with all `required` flags among `typeBits`; throws if none.
  uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const;
  bool hasMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const;

  // Debug names and labels (no-ops without VK_EXT_debug_utils).
  void setName(VkObjectType type, uint64_t handle, const std::string& name) const;
  void beginLabel(VkCommandBuffer cmd, const char* name) const;
  void endLabel(VkCommandBuffer cmd) const;

  // Records into a fresh command buffer, submits it and waits (bounded; a hang throws).
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record) const;

  PFN_vkCmdPushDescriptorSetKHR cmdPushDescriptorSet = nullptr;

 private:
  void createInstance(bool wantValidation, const std::vector<std::string>& extraExtensions);
  void pickPhysicalDevice(const std::string& selector);
  void createDevice(bool swapchain, uint64_t testMaxAllocationBytes, bool testRequireFullSubgroups);
  void release() noexcept;  // frees whatever handles exist, in reverse creation order
  static VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(
      VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  // Declared in creation order; the destructor frees in reverse.
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  VkCommandPool commandPool_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memoryProperties_{};
  Capabilities caps_;
  bool validation_ = false;
  bool debugUtils_ = false;
  mutable std::atomic<uint32_t> validationMessages_{0};
  PFN_vkSetDebugUtilsObjectNameEXT setObjectName_ = nullptr;
  PFN_vkCmdBeginDebugUtilsLabelEXT cmdBeginLabel_ = nullptr;
  PFN_vkCmdEndDebugUtilsLabelEXT cmdEndLabel_ = nullptr;
};

}  // namespace osr::vk
