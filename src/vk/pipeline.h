// A compute pipeline built from one embedded SPIR-V module. Buffers are bound with push
// descriptors (storage buffers at bindings 0..n-1), so a pass needs no descriptor pools or
// sets; push constants carry the pass's Push struct from its shaders/shared header.
#pragma once
#include <vulkan/vulkan.h>

#include <cstring>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include "shaders/shader_id.h"
#include "vk/buffer.h"
#include "vk/context.h"

namespace osr::vk {

// One specialization constant: `id` is the constant_id in the shader.
struct SpecConstant {
  uint32_t id;
  uint32_t bits;  // value as 32-bit pattern (use specFloat for floats)
};
inline SpecConstant specUint(uint32_t id, uint32_t v) { return {id, v}; }
inline SpecConstant specFloat(uint32_t id, float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  return {id, bits};
}

class ComputePipeline {
 public:
  ComputePipeline() = default;
  // bindingCount storage buffers; pushBytes of push constants (0 for none).
  ComputePipeline(const Context& ctx, shaders::Id shader, uint32_t bindingCount,
                  uint32_t pushBytes, const std::vector<SpecConstant>& spec = {});
  // Bindings of the given types (storage buffers, uniform texel buffers), in slot order;
  // bound with bindDescriptors().
  ComputePipeline(const Context& ctx, shaders::Id shader, std::vector<VkDescriptorType> types,
                  uint32_t pushBytes, const std::vector<SpecConstant>& spec = {});
  ~ComputePipeline();
  ComputePipeline(ComputePipeline&& other) noexcept;
  ComputePipeline& operator=(ComputePipeline&& other) noexcept;
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  const char* name() const { return name_; }

  // Binds the pipeline, pushes the buffers (slot i = buffers[i]) and the push constants.
  // Throws DeviceError if a range exceeds the device's maxStorageBufferRange.
  void bind(VkCommandBuffer cmd, std::initializer_list<BufferRange> buffers,
            const void* push = nullptr) const;
  template <class Push>
  void bind(VkCommandBuffer cmd, std::initializer_list<BufferRange> buffers,
            const Push& push) const {
    static_assert(!std::is_pointer_v<Push>);
    checkPushSize(sizeof(Push));
    bind(cmd, buffers, static_cast<const void*>(&push));
  }
  // bind() for a list assembled at run time, e.g. a pass's own buffers followed by
  // scene::GpuScene::bindings().
  void bindSpan(VkCommandBuffer cmd, std::span<const BufferRange> buffers,
                const void* push = nullptr) const;
  template <class Push>
  void bindSpan(VkCommandBuffer cmd, std::span<const BufferRange> buffers,
                const Push& push) const {
    static_assert(!std::is_pointer_v<Push>);
    checkPushSize(sizeof(Push));
    bindSpan(cmd, buffers, static_cast<const void*>(&push));
  }
  // Dispatches groups, splitting counts beyond the device limit is the caller's job.
  void dispatch(VkCommandBuffer cmd, uint32_t x, uint32_t y = 1, uint32_t z = 1) const;
  void dispatchIndirect(VkCommandBuffer cmd, const Buffer& args, VkDeviceSize offset) const;

  // One slot for bindDescriptors(): a buffer range, or a texel view for texel-buffer slots.
  struct Descriptor {
    BufferRange buffer;
    VkBufferView texel = VK_NULL_HANDLE;
    Descriptor(const BufferRange& b) : buffer(b) {}  // NOLINT: buffers convert implicitly
    Descriptor(VkBufferView view) : texel(view) {}   // NOLINT
  };
  // bind() for pipelines made with descriptor types; push must match pushBytes.
  void bindDescriptors(VkCommandBuffer cmd, std::initializer_list<Descriptor> slots,
                       const void* push) const;
  // bindDescriptors() for a list assembled at run time (a pass's slots + bvh::Bvh::descriptors).
  void bindDescriptorSpan(VkCommandBuffer cmd, std::span<const Descriptor> slots,
                          const void* push) const;
  template <class Push>
  void bindDescriptorSpan(VkCommandBuffer cmd, std::span<const Descriptor> slots,
                          const Push& push) const {
    static_assert(!std::is_pointer_v<Push>);
    checkPushSize(sizeof(Push));
    bindDescriptorSpan(cmd, slots, static_cast<const void*>(&push));
  }

 private:
  void checkPushSize(size_t bytes) const;
  void release();
  const Context* ctx_ = nullptr;
  const char* name_ = "";
  uint32_t bindingCount_ = 0;
  uint32_t pushBytes_ = 0;
  std::vector<VkDescriptorType> types_;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

// Number of workgroups of `groupSize` covering `items`.
inline uint32_t groupCount(uint64_t items, uint32_t groupSize) {
  return static_cast<uint32_t>((items + groupSize - 1) / groupSize);
}

}  // namespace osr::vk
