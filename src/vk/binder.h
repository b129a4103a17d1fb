// Bindings by slot name: a pass fills one Binder per pipeline with set(kBinding..., buffer) and
// setTexel(kBinding..., view), using the slot constants of its shaders/shared header, then
// binds it (pipeline, push descriptors, push constants) once per dispatch. Nothing is
// positional: a slot left unset or given the wrong kind of descriptor throws, naming the
// pipeline and the slot. Fixed capacity, no heap: cheap enough to bind per dispatch.
#pragma once
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <type_traits>

#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace osr::vk {

class Binder {
 public:
  static constexpr uint32_t kMaxSlots = 32;

  // `pipeline` must outlive the binder.
  explicit Binder(const ComputePipeline& pipeline);

  // Storage-buffer slot: the range (a whole Buffer converts). Throws if `slot` is out of range,
  // not a storage-buffer slot, the buffer is invalid or the range exceeds
  // maxStorageBufferRange.
  Binder& set(uint32_t slot, const BufferRange& range);
  Binder& setRange(uint32_t slot, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize bytes) {
    return set(slot, BufferRange(buffer, offset, bytes));
  }
  // Uniform-texel-buffer slot. Throws if the slot is not one or the view is null.
  Binder& setTexel(uint32_t slot, VkBufferView view);
  bool isSet(uint32_t slot) const { return slot < count_ && (setMask_ >> slot & 1u); }

  // Binds the pipeline, pushes every slot's descriptor and the push constants (sized as the
  // pipeline declares). Throws DeviceError naming the first unset slot.
  template <class Push>
  void bind(VkCommandBuffer cmd, const Push& push) const {
    static_assert(!std::is_pointer_v<Push> && std::is_trivially_copyable_v<Push>);
    bindRaw(cmd, &push, sizeof(Push));
  }
  // For pipelines without push constants.
  void bind(VkCommandBuffer cmd) const { bindRaw(cmd, nullptr, 0); }

  const ComputePipeline& pipeline() const { return *pipeline_; }

 private:
  void bindRaw(VkCommandBuffer cmd, const void* push, size_t pushBytes) const;
  [[noreturn]] void fail(uint32_t slot, const std::string& what) const;

  const ComputePipeline* pipeline_;
  uint32_t count_;
  uint32_t setMask_ = 0;
  std::array<VkDescriptorBufferInfo, kMaxSlots> buffers_{};
  std::array<VkBufferView, kMaxSlots> views_{};
};

}  // namespace osr::vk
