// Constructors that throw halfway free what they made: Context with a --device that matches
// nothing (or a failing enumeration), Buffer when binding its memory fails, ComputePipeline
// when the pipeline itself fails. The validation layer cannot see a leaked VkInstance (it
// reports leaks when the instance is destroyed), so this executable interposes the Vulkan
// entry points osr_core calls: each wrapper counts live handles and forwards to the loader
// (dlsym RTLD_NEXT), and can be told to fail one entry point, as a driver out of memory would.
// It is its own executable so that no other test runs through the wrappers.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <cstring>
#include <map>
#include <string>

#include "common/error.h"
#include "common/vk_test.h"
#include "shaders/shared/util_fill.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

using namespace osr;

namespace {

std::map<std::string, int> gLive;  // handle kind -> created minus destroyed
const char* gFail = nullptr;       // entry point that returns an error instead of running

bool failing(const char* entry) { return gFail && std::strcmp(gFail, entry) == 0; }

template <class Fn>
Fn real(const char* entry) {
  void* f = dlsym(RTLD_NEXT, entry);
  if (!f) std::abort();
  return reinterpret_cast<Fn>(f);
}

// Makes `entry` fail while in scope.
struct FailIn {
  explicit FailIn(const char* entry) { gFail = entry; }
  ~FailIn() { gFail = nullptr; }
};

}  // namespace

// Wrappers with the exact prototypes of vulkan_core.h; the static osr_core links to these.
extern "C" {

#define OSR_COUNT_CREATE(Kind, Entry, ...)                                     \
  if (failing(#Entry)) return VK_ERROR_OUT_OF_HOST_MEMORY;                     \
  static const auto fn = real<PFN_##Entry>(#Entry);                            \
  VkResult r = fn(__VA_ARGS__);                                                \
  if (r == VK_SUCCESS) ++gLive[Kind];                                          \
  return r;
#define OSR_COUNT_DESTROY(Kind, Entry, handle, ...)                            \
  static const auto fn = real<PFN_##Entry>(#Entry);                            \
  if (handle) --gLive[Kind];                                                   \
  fn(__VA_ARGS__);

VKAPI_ATTR VkResult VKAPI_CALL vkCreateInstance(const VkInstanceCreateInfo* i,
                                                const VkAllocationCallbacks* a, VkInstance* o) {
  OSR_COUNT_CREATE("instance", vkCreateInstance, i, a, o)
}
VKAPI_ATTR void VKAPI_CALL vkDestroyInstance(VkInstance h, const VkAllocationCallbacks* a) {
  OSR_COUNT_DESTROY("instance", vkDestroyInstance, h, h, a)
}
VKAPI_ATTR VkResult VKAPI_CALL vkAllocateMemory(VkDevice d, const VkMemoryAllocateInfo* i,
                                                const VkAllocationCallbacks* a, VkDeviceMemory* o) {
  OSR_COUNT_CREATE("memory", vkAllocateMemory, d, i, a, o)
}
VKAPI_ATTR void VKAPI_CALL vkFreeMemory(VkDevice d, VkDeviceMemory h, const VkAllocationCallbacks* a) {
  OSR_COUNT_DESTROY("memory", vkFreeMemory, h, d, h, a)
}
// vkCreate<Name> and vkDestroy<Name> of a device object, counted as `kind`.
#define OSR_COUNTED_DEVICE_OBJECT(kind, Name)                                                   \
  VKAPI_ATTR VkResult VKAPI_CALL vkCreate##Name(VkDevice d, const Vk##Name##CreateInfo* i,     \
                                                const VkAllocationCallbacks* a, Vk##Name* o) { \
    OSR_COUNT_CREATE(kind, vkCreate##Name, d, i, a, o)                                         \
  }                                                                                            \
  VKAPI_ATTR void VKAPI_CALL vkDestroy##Name(VkDevice d, Vk##Name h,                           \
                                             const VkAllocationCallbacks* a) {                 \
    OSR_COUNT_DESTROY(kind, vkDestroy##Name, h, d, h, a)                                       \
  }
OSR_COUNTED_DEVICE_OBJECT("buffer", Buffer)
OSR_COUNTED_DEVICE_OBJECT("shader module", ShaderModule)
OSR_COUNTED_DEVICE_OBJECT("set layout", DescriptorSetLayout)
OSR_COUNTED_DEVICE_OBJECT("pipeline layout", PipelineLayout)
// Failure points only: their objects are counted above.
VKAPI_ATTR VkResult VKAPI_CALL vkBindBufferMemory(VkDevice d, VkBuffer b, VkDeviceMemory m,
                                                  VkDeviceSize o) {
  if (failing("vkBindBufferMemory")) return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  static const auto fn = real<PFN_vkBindBufferMemory>("vkBindBufferMemory");
  return fn(d, b, m, o);
}
VKAPI_ATTR VkResult VKAPI_CALL vkCreateComputePipelines(VkDevice d, VkPipelineCache c, uint32_t n,
                                                        const VkComputePipelineCreateInfo* i,
                                                        const VkAllocationCallbacks* a, VkPipeline* o) {
  if (failing("vkCreateComputePipelines")) return VK_ERROR_OUT_OF_HOST_MEMORY;
  static const auto fn = real<PFN_vkCreateComputePipelines>("vkCreateComputePipelines");
  return fn(d, c, n, i, a, o);
}
VKAPI_ATTR VkResult VKAPI_CALL vkEnumerateDeviceExtensionProperties(VkPhysicalDevice p, const char* l,
                                                                    uint32_t* n,
                                                                    VkExtensionProperties* o) {
  if (failing("vkEnumerateDeviceExtensionProperties")) return VK_ERROR_OUT_OF_HOST_MEMORY;
  static const auto fn =
      real<PFN_vkEnumerateDeviceExtensionProperties>("vkEnumerateDeviceExtensionProperties");
  return fn(p, l, n, o);
}

}  // extern "C"

namespace {

// The kinds with live handles (gLive without its zero entries), to compare before and after.
std::map<std::string, int> live() {
  std::map<std::string, int> out;
  for (auto [kind, n] : gLive)
    if (n) out[kind] = n;
  return out;
}

// Constructs a Context with `device`, validation on; returns the error text ("" if none).
template <class Error>
std::string contextError(const std::string& device) {
  vk::ContextOptions options;
  options.validation = true;
  options.device = device;
  try {
    vk::Context ctx(options);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ExceptionSafety, ContextWithABadDeviceFreesTheInstance) {
  test::context();  // the shared context stays alive throughout; count from here
  const auto before = live();
  EXPECT_NE(contextError<InputError>("no-such-device-name").find("no device name matches"),
            std::string::npos);
  EXPECT_NE(contextError<InputError>("99").find("device(s); see --list-devices"), std::string::npos);
  EXPECT_EQ(live(), before) << "live instances: " << gLive["instance"] << ", before "
                           << before.at("instance");
  // A Context that succeeds is counted and freed too: the wrappers see what osr_core does.
  const int instances = gLive["instance"];
  {
    vk::Context ok;
    EXPECT_EQ(gLive["instance"], instances + 1);
  }
  EXPECT_EQ(live(), before);
}

// An enumeration that fails is a DeviceError naming it (not an empty list), and the Context
// made so far is freed.
TEST(ExceptionSafety, FailedEnumerationIsReportedAndFreesTheContext) {
  test::context();
  const auto before = live();
  std::string error;
  {
    FailIn fail("vkEnumerateDeviceExtensionProperties");
    error = contextError<DeviceError>("");
  }
  EXPECT_EQ(error.rfind("vkEnumerateDeviceExtensionProperties: VK_ERROR_OUT_OF_HOST_MEMORY", 0), 0u)
      << error;
  EXPECT_EQ(live(), before);
}

TEST(ExceptionSafety, BufferFreesItsMemoryWhenBindingFails) {
  auto& ctx = test::context();
  const auto before = live();
  for (auto use : {vk::MemoryUse::DeviceLocal, vk::MemoryUse::HostUpload, vk::MemoryUse::HostReadback}) {
    FailIn fail("vkBindBufferMemory");
    EXPECT_THROW(vk::Buffer(ctx, 4096, use, "doomed"), DeviceError);
  }
  EXPECT_EQ(live(), before) << "live buffers " << gLive["buffer"] << ", memories " << gLive["memory"];
  // The wrappers do see Buffer's handles: one that succeeds is counted until destroyed.
  const int buffers = gLive["buffer"], memories = gLive["memory"];
  {
    vk::Buffer ok(ctx, 4096, vk::MemoryUse::DeviceLocal, "ok");
    EXPECT_EQ(gLive["buffer"], buffers + 1);
    EXPECT_EQ(gLive["memory"], memories + 1);
  }
  EXPECT_EQ(live(), before);
}

TEST(ExceptionSafety, ComputePipelineFreesItsLayoutsWhenThePipelineFails) {
  auto& ctx = test::context();
  const auto before = live();
  {
    FailIn fail("vkCreateComputePipelines");
    EXPECT_THROW(vk::ComputePipeline(ctx, shaders::Id::util_fill, 1, sizeof(gpu::util_fill::Push)),
                 DeviceError);
  }
  EXPECT_EQ(live(), before) << "live modules " << gLive["shader module"] << ", set layouts "
                           << gLive["set layout"] << ", pipeline layouts " << gLive["pipeline layout"];
  // The same pipeline builds when nothing fails, is counted, and frees everything when destroyed.
  const int modules = gLive["shader module"], layouts = gLive["pipeline layout"];
  {
    vk::ComputePipeline ok(ctx, shaders::Id::util_fill, 1, sizeof(gpu::util_fill::Push));
    EXPECT_EQ(gLive["shader module"], modules + 1);
    EXPECT_EQ(gLive["pipeline layout"], layouts + 1);
  }
  EXPECT_EQ(live(), before);
}
