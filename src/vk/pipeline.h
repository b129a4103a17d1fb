// A compute pipeline built from one embedded SPIR-V module. Buffers are bound with push
// descriptors through vk::Binder (vk/binder.h), by the slot constants of the pass's
// shaders/shared header, so a pass needs no descriptor pools or sets; push constants carry the
// pass's Push struct from the same header.
#pragma once
#include <vulkan/vulkan.h>

#include <cstring>
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
  // Bindings of the given types (storage buffers, uniform texel buffers), types[slot].
  ComputePipeline(const Context& ctx, shaders::Id shader, std::vector<VkDescriptorType> types,
                  uint32_t pushBytes, const std::vector<SpecConstant>& spec = {});
  ~ComputePipeline();
  ComputePipeline(ComputePipeline&& other) noexcept;
  ComputePipeline& operator=(ComputePipeline&& other) noexcept;
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  const char* name() const { return name_; }

  // Binding slots (set by vk::Binder, which is how passes bind: vk/binder.h).
  uint32_t slotCount() const { return bindingCount_; }
  VkDescriptorType slotType(uint32_t slot) const { return types_[slot]; }
  const Context& context() const { return *ctx_; }
  // Binds the pipeline, pushes `writes` (one per slot) and pushBytes of push constants, which
  // must equal the pipeline's declared size. Called by vk::Binder.
  void bindWrites(VkCommandBuffer cmd, std::span<const VkWriteDescriptorSet> writes,
                  const void* push, size_t pushBytes) const;
  // Dispatches groups, splitting counts beyond the device limit is the caller's job.
  void dispatch(VkCommandBuffer cmd, uint32_t x, uint32_t y = 1, uint32_t z = 1) const;
  void dispatchIndirect(VkCommandBuffer cmd, const Buffer& args, VkDeviceSize offset) const;

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
