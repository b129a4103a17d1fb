#include "vk/context.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "common/error.h"
#include "vk/check.h"
#include "vk/debug_labels.h"

#if defined(__SANITIZE_ADDRESS__)
#define OSR_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define OSR_ASAN 1
#endif
#endif
#ifdef OSR_ASAN
#include <dlfcn.h>
#include <link.h>
#endif

namespace osr::vk {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
// A submission that takes longer than this is treated as a hung device, not waited on forever.
constexpr uint64_t kSubmitTimeoutNs = 600ull * 1000 * 1000 * 1000;

const char* typeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

// Lower is preferred: discrete, integrated, virtual, CPU (lavapipe), other.
int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// The layer's spec version, 0 when it is not installed.
uint32_t instanceLayerVersion(const char* name) {
  uint32_t count = 0;
  check(vkEnumerateInstanceLayerProperties(&count, nullptr), "vkEnumerateInstanceLayerProperties");
  std::vector<VkLayerProperties> layers(count);
  check(vkEnumerateInstanceLayerProperties(&count, layers.data()),
        "vkEnumerateInstanceLayerProperties");
  for (auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return l.specVersion;
  return 0;
}

bool hasInstanceExtension(const char* name) {
  uint32_t count = 0;
  check(vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr),
        "vkEnumerateInstanceExtensionProperties");
  std::vector<VkExtensionProperties> exts(count);
  check(vkEnumerateInstanceExtensionProperties(nullptr, &count, exts.data()),
        "vkEnumerateInstanceExtensionProperties");
  for (auto& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

bool hasDeviceExtension(VkPhysicalDevice pd, const char* name) {
  uint32_t count = 0;
  check(vkEnumerateDeviceExtensionProperties(pd, nullptr, &count, nullptr),
        "vkEnumerateDeviceExtensionProperties");
  std::vector<VkExtensionProperties> exts(count);
  check(vkEnumerateDeviceExtensionProperties(pd, nullptr, &count, exts.data()),
        "vkEnumerateDeviceExtensionProperties");
  for (auto& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

// Under AddressSanitizer only. LeakSanitizer checks at exit, after the Vulkan loader has
// unloaded the drivers and layers; what they keep for the life of the process (lavapipe's
// one-time set-up during vkEnumeratePhysicalDevices) then shows as a leak from an unknown
// module that no suppression can name. Kept loaded, it is reachable, and any real leak in
// them carries their names for tests/sanitizers/lsan.supp.
void keepVulkanModulesLoaded() {
#ifdef OSR_ASAN
  std::vector<std::string> names;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* out) {
        const char* name = info->dlpi_name;
        if (name && (std::strstr(name, "libvulkan_") || std::strstr(name, "libVkLayer_")))
          static_cast<std::vector<std::string>*>(out)->push_back(name);
        return 0;
      },
      &names);
  // dlopen outside the iteration, which holds the dynamic linker's lock.
  for (const std::string& name : names) dlopen(name.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
#endif
}

VkInstance makeInstance(const std::vector<const char*>& layers,
                        const std::vector<const char*>& extensions) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "osr-vk";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  VkResult r = vkCreateInstance(&info, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw DeviceError("vulkan: no Vulkan 1.2 driver found (install mesa-vulkan-drivers)");
  check(r, "vkCreateInstance");
  keepVulkanModulesLoaded();
  return instance;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  uint32_t count = 0;
  check(vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(count);
  check(vkEnumeratePhysicalDevices(instance, &count, devices.data()),
        "vkEnumeratePhysicalDevices");
  return devices;
}

}  // namespace

bool commandLabelsSafe(uint32_t validationLayerSpecVersion) {
  // Upstream's fix (2a430d9d3, "layers: Fix debug label race conditions") is in 1.3.243.
  return validationLayerSpecVersion == 0 ||
         validationLayerSpecVersion >= VK_MAKE_API_VERSION(0, 1, 3, 243);
}

SubgroupPlan planSubgroups(const std::string& deviceName, uint32_t size, uint32_t minSize,
                           uint32_t maxSize, bool canRequireFull, bool forceRequireFull) {
  auto refuse = [&](const std::string& why) {
    return DeviceError("vulkan: device \"" + deviceName + "\" " + why +
                       "; osr-vk's subgroup passes need one power-of-two size from 4 to 64 "
                       "(docs/subgroups.md)");
  };
  auto supported = [](uint32_t s) { return s >= 4 && s <= 64 && (s & (s - 1)) == 0; };
  if (!supported(size)) throw refuse("has subgroups of " + std::to_string(size) + " invocations");
  if (minSize > size || maxSize < size) minSize = maxSize = size;  // a driver's odd report
  const bool varies = minSize != maxSize;
  if (varies && !canRequireFull)
    throw refuse("may run subgroups of " + std::to_string(minSize) + " to " +
                 std::to_string(maxSize) + " invocations and cannot be asked for full ones");
  return {minSize, maxSize, (varies || forceRequireFull) && canRequireFull};
}

std::vector<DeviceInfo> listDevices() {
  VkInstance instance = makeInstance({}, {});
  std::vector<VkPhysicalDevice> devices;
  try {
    devices = physicalDevices(instance);
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  std::vector<DeviceInfo> out;
  for (uint32_t i = 0; i < devices.size(); ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(devices[i], &p);
    out.push_back({i, p.deviceName, typeName(p.deviceType), p.apiVersion});
  }
  vkDestroyInstance(instance, nullptr);
  return out;
}

Context::Context(const ContextOptions& options) {
  // A constructor that throws runs no destructor: free what was made so far (e.g. the
  // instance and messenger when --device matches nothing), then rethrow.
  try {
    createInstance(options.validation || envFlag("OSR_VALIDATION"), options.instanceExtensions);
    pickPhysicalDevice(options.device);
    createDevice(options.swapchain, options.testMaxAllocationBytes,
                 options.testRequireFullSubgroups);
  } catch (...) {
    release();
    throw;
  }
  if (options.verbose) {
    std::fprintf(stderr,
                 "osr-vk: device \"%s\" (%s), subgroup %u, maxStorageBufferRange %llu MiB, "
                 "fp16 %s, 16-bit storage %s, unified memory %s, validation %s\n",
                 caps_.deviceName.c_str(), typeName(caps_.deviceType), caps_.subgroupSize,
                 static_cast<unsigned long long>(caps_.maxStorageBufferRange >> 20),
                 caps_.shaderFloat16 ? "yes" : "no", caps_.storageBuffer16Bit ? "yes" : "no",
                 caps_.unifiedMemory ? "yes" : "no", validation_ ? "on" : "off");
  }
}

Context::~Context() { release(); }

void Context::release() noexcept {
  if (device_) {
    // Nothing to do with a failure here: the device is destroyed either way.
    (void)vkDeviceWaitIdle(device_);
    if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  commandPool_ = VK_NULL_HANDLE;
  device_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

void Context::createInstance(bool wantValidation, const std::vector<std::string>& extraExtensions) {
  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  for (const std::string& e : extraExtensions) {
    if (!hasInstanceExtension(e.c_str()))
      throw DeviceError("vulkan: the Vulkan loader lacks instance extension " + e);
    extensions.push_back(e.c_str());
  }
  uint32_t layerVersion = 0;
  if (wantValidation) {
    layerVersion = instanceLayerVersion(kValidationLayer);
    if (layerVersion == 0)
      throw DeviceError(std::string("vulkan: validation requested but ") + kValidationLayer +
                        " is not installed (Debian package vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    validation_ = true;
  }
  debugUtils_ = hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  if (debugUtils_) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  instance_ = makeInstance(layers, extensions);

  if (debugUtils_) {
    setObjectName_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
  }
  // The layer may also be switched on from outside (vkconfig's variables): labels follow the
  // installed layer's version then too.
  const char* outside[] = {"VK_INSTANCE_LAYERS", "VK_LOADER_LAYERS_ENABLE"};
  for (const char* var : outside) {
    const char* v = std::getenv(var);
    if (layerVersion == 0 && v && lower(v).find("validation") != std::string::npos)
      layerVersion = instanceLayerVersion(kValidationLayer);
  }
  if (debugUtils_ && commandLabelsSafe(layerVersion)) {
    cmdBeginLabel_ = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
        vkGetInstanceProcAddr(instance_, "vkCmdBeginDebugUtilsLabelEXT"));
    cmdEndLabel_ = reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(
        vkGetInstanceProcAddr(instance_, "vkCmdEndDebugUtilsLabelEXT"));
  }
  if (validation_ && debugUtils_) {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = &Context::debugCallback;
    info.pUserData = this;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    check(create(instance_, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
}

VKAPI_ATTR VkBool32 VKAPI_CALL Context::debugCallback(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<Context*>(user);
  self->validationMessages_.fetch_add(1);
  const char* level =
      (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  std::fprintf(stderr, "osr-vk: validation %s: %s\n", level, data->pMessage);
  return VK_FALSE;
}

void Context::pickPhysicalDevice(const std::string& selector) {
  auto devices = physicalDevices(instance_);
  if (devices.empty()) throw DeviceError("vulkan: no physical device found");
  auto props = [](VkPhysicalDevice d) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    return p;
  };
  auto usable = [](VkPhysicalDevice d) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    return p.apiVersion >= VK_API_VERSION_1_2;
  };

  if (selector.empty()) {
    int bestRank = 1 << 30;
    for (auto d : devices) {
      if (!usable(d)) continue;
      int rank = typeRank(props(d).deviceType);
      if (rank < bestRank) bestRank = rank, physicalDevice_ = d;
    }
    if (!physicalDevice_) throw DeviceError("vulkan: no Vulkan 1.2 device found");
  } else if (std::all_of(selector.begin(), selector.end(), ::isdigit)) {
    size_t index = std::stoul(selector);
    if (index >= devices.size())
      throw InputError("--device " + selector + ": only " + std::to_string(devices.size()) +
                       " device(s); see --list-devices");
    physicalDevice_ = devices[index];
  } else {
    for (auto d : devices)
      if (lower(props(d).deviceName).find(lower(selector)) != std::string::npos) {
        physicalDevice_ = d;
        break;
      }
    if (!physicalDevice_)
      throw InputError("--device " + selector + ": no device name matches; see --list-devices");
  }
  if (!usable(physicalDevice_))
    throw DeviceError(std::string("vulkan: device \"") + props(physicalDevice_).deviceName +
                      "\" does not support Vulkan 1.2");
}

void Context::createDevice(bool swapchain, uint64_t testMaxAllocationBytes,
                           bool testRequireFullSubgroups) {
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceMaintenance3Properties maintenance3{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
  VkPhysicalDeviceSubgroupSizeControlPropertiesEXT sizeControl{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_PROPERTIES_EXT};
  const bool sizeControlExt =
      hasDeviceExtension(physicalDevice_, VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME);
  props2.pNext = &subgroup;
  subgroup.pNext = &maintenance3;
  if (sizeControlExt) maintenance3.pNext = &sizeControl;
  vkGetPhysicalDeviceProperties2(physicalDevice_, &props2);
  const VkPhysicalDeviceLimits& limits = props2.properties.limits;

  VkPhysicalDeviceFeatures2 features2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceSubgroupSizeControlFeaturesEXT sizeFeatures{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES_EXT};
  features2.pNext = &f11;
  f11.pNext = &f12;
  if (sizeControlExt) f12.pNext = &sizeFeatures;
  vkGetPhysicalDeviceFeatures2(physicalDevice_, &features2);

  const SubgroupPlan subgroups = planSubgroups(
      props2.properties.deviceName, subgroup.subgroupSize,
      sizeControlExt ? sizeControl.minSubgroupSize : subgroup.subgroupSize,
      sizeControlExt ? sizeControl.maxSubgroupSize : subgroup.subgroupSize,
      sizeControlExt && sizeFeatures.subgroupSizeControl && sizeFeatures.computeFullSubgroups,
      testRequireFullSubgroups);

  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, families.data());
  // Prefer a queue that does compute and graphics (the viewer presents from it), else compute.
  int chosen = -1;
  for (uint32_t i = 0; i < familyCount && chosen < 0; ++i)
    if ((families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) &&
        (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT))
      chosen = static_cast<int>(i);
  for (uint32_t i = 0; i < familyCount && chosen < 0; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) chosen = static_cast<int>(i);
  if (chosen < 0)
    throw DeviceError(std::string("vulkan: device \"") + props2.properties.deviceName +
                      "\" has no compute queue");
  queueFamily_ = static_cast<uint32_t>(chosen);

  if (!hasDeviceExtension(physicalDevice_, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
    throw DeviceError(std::string("vulkan: device \"") + props2.properties.deviceName +
                      "\" lacks " + VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
  std::vector<const char*> extensions = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  if (swapchain) {
    // Asking for a window on a device that cannot show one is like asking without a display:
    // the viewer's contract is one line suggesting --offline and exit 2.
    if (!hasDeviceExtension(physicalDevice_, VK_KHR_SWAPCHAIN_EXTENSION_NAME))
      throw InputError(std::string("vulkan: device \"") + props2.properties.deviceName +
                       "\" cannot present to a window (no " VK_KHR_SWAPCHAIN_EXTENSION_NAME
                       "); use --offline");
    extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  }

  // Enable only what we use, and only where the device has it.
  VkPhysicalDeviceFeatures2 enable2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  VkPhysicalDeviceVulkan11Features e11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  enable2.pNext = &e11;
  e11.pNext = &e12;
  enable2.features.shaderInt64 = features2.features.shaderInt64;
  enable2.features.shaderInt16 = features2.features.shaderInt16;
  e11.storageBuffer16BitAccess = f11.storageBuffer16BitAccess;
  e12.shaderFloat16 = f12.shaderFloat16;
  e12.shaderInt8 = f12.shaderInt8;
  e12.storageBuffer8BitAccess = f12.storageBuffer8BitAccess;
  e12.scalarBlockLayout = f12.scalarBlockLayout;
  e12.hostQueryReset = f12.hostQueryReset;
  e12.bufferDeviceAddress = f12.bufferDeviceAddress;
  VkPhysicalDeviceSubgroupSizeControlFeaturesEXT enableSizeControl{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES_EXT};
  if (subgroups.requireFull) {
    enableSizeControl.subgroupSizeControl = VK_TRUE;
    enableSizeControl.computeFullSubgroups = VK_TRUE;
    e12.pNext = &enableSizeControl;
    extensions.push_back(VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME);
  }

  float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queueInfo.queueFamilyIndex = queueFamily_;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &enable2;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  check(vkCreateDevice(physicalDevice_, &info, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
  cmdPushDescriptorSet = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
      vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));

  VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  poolInfo.queueFamilyIndex = queueFamily_;
  check(vkCreateCommandPool(device_, &poolInfo, nullptr, &commandPool_), "vkCreateCommandPool");

  vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memoryProperties_);
  caps_.deviceName = props2.properties.deviceName;
  caps_.deviceType = props2.properties.deviceType;
  caps_.subgroupSize = subgroup.subgroupSize;
  caps_.minSubgroupSize = subgroups.minSize;
  caps_.maxSubgroupSize = subgroups.maxSize;
  caps_.requireFullSubgroups = subgroups.requireFull;
  const VkSubgroupFeatureFlags shuffles = VK_SUBGROUP_FEATURE_SHUFFLE_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_RELATIVE_BIT |
                                          VK_SUBGROUP_FEATURE_VOTE_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT;
  caps_.subgroupShuffle = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
                          (subgroup.supportedOperations & shuffles) == shuffles;
  caps_.maxStorageBufferRange = limits.maxStorageBufferRange;
  caps_.maxMemoryAllocationSize = maintenance3.maxMemoryAllocationSize;
  if (testMaxAllocationBytes > 0)
    caps_.maxMemoryAllocationSize = std::min<uint64_t>(caps_.maxMemoryAllocationSize, testMaxAllocationBytes);
  caps_.maxTexelBufferElements = limits.maxTexelBufferElements;
  for (int i = 0; i < 3; ++i) caps_.maxComputeWorkGroupCount[i] = limits.maxComputeWorkGroupCount[i];
  caps_.maxPushConstantsSize = limits.maxPushConstantsSize;
  caps_.timestampPeriodNs = limits.timestampPeriod;
  caps_.timestamps = limits.timestampComputeAndGraphics && families[queueFamily_].timestampValidBits > 0;
  caps_.shaderFloat16 = e12.shaderFloat16;
  caps_.storageBuffer16Bit = e11.storageBuffer16BitAccess;
  caps_.shaderInt64 = enable2.features.shaderInt64;
  caps_.bufferDeviceAddress = e12.bufferDeviceAddress;
  caps_.unifiedMemory = true;
  for (uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i) {
    auto f = memoryProperties_.memoryTypes[i].propertyFlags;
    if ((f & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) && !(f & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)) {
      caps_.unifiedMemory = false;
      break;
    }
  }
  setName(VK_OBJECT_TYPE_DEVICE, reinterpret_cast<uint64_t>(device_), "osr-vk device");
  setName(VK_OBJECT_TYPE_QUEUE, reinterpret_cast<uint64_t>(queue_), "osr-vk compute queue");
  setName(VK_OBJECT_TYPE_COMMAND_POOL, reinterpret_cast<uint64_t>(commandPool_), "osr-vk pool");
}

bool Context::hasMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const {
  for (uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) &&
        (memoryProperties_.memoryTypes[i].propertyFlags & required) == required)
      return true;
  return false;
}

uint32_t Context::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const {
  for (uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) &&
        (memoryProperties_.memoryTypes[i].propertyFlags & required) == required)
      return i;
  throw DeviceError("vulkan: no memory type with flags " + std::to_string(required));
}

void Context::setName(VkObjectType type, uint64_t handle, const std::string& name) const {
  if (!setObjectName_ || !handle) return;
  VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name.c_str();
  // Best effort: a debug name is an aid for tools, and failing to attach one (out of host
  // memory) must not fail the object it names.
  (void)setObjectName_(device_, &info);
}

void Context::beginLabel(VkCommandBuffer cmd, const char* name) const {
  if (!cmdBeginLabel_) return;
  VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
  label.pLabelName = name;
  cmdBeginLabel_(cmd, &label);
}

void Context::endLabel(VkCommandBuffer cmd) const {
  if (cmdEndLabel_) cmdEndLabel_(cmd);
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) const {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = commandPool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  check(vkAllocateCommandBuffers(device_, &alloc, &cmd), "vkAllocateCommandBuffers");
  VkFence fence = VK_NULL_HANDLE;
  struct Cleanup {
    const Context* ctx;
    VkCommandBuffer& cmd;
    VkFence& fence;
    bool pending = false;  // a timed-out submission may still run: leak rather than free it
    ~Cleanup() {
      if (pending) return;
      if (fence) vkDestroyFence(ctx->device_, fence, nullptr);
      vkFreeCommandBuffers(ctx->device_, ctx->commandPool_, 1, &cmd);
    }
  } cleanup{this, cmd, fence};

  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
  record(cmd);
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

  VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkCreateFence(device_, &fenceInfo, nullptr, &fence), "vkCreateFence");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  check(vkQueueSubmit(queue_, 1, &submit, fence), "vkQueueSubmit");
  VkResult r = vkWaitForFences(device_, 1, &fence, VK_TRUE, kSubmitTimeoutNs);
  if (r == VK_TIMEOUT) {
    cleanup.pending = true;
    throw DeviceError("vulkan: submission did not finish within 600 s");
  }
  check(r, "vkWaitForFences");
}

}  // namespace osr::vk
