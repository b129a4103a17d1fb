#include "vk/binder.h"

#include <string>

#include "common/error.h"

namespace osr::vk {

Binder::Binder(const ComputePipeline& pipeline)
    : pipeline_(&pipeline), count_(pipeline.slotCount()) {
  if (count_ > kMaxSlots)
    throw DeviceError(std::string(pipeline.name()) + ": " + std::to_string(count_) +
                      " binding slots, the binder holds " + std::to_string(kMaxSlots));
}

void Binder::fail(uint32_t slot, const std::string& what) const {
  throw DeviceError(std::string(pipeline_->name()) + ": slot " + std::to_string(slot) + " " + what);
}

Binder& Binder::set(uint32_t slot, const BufferRange& r) {
  if (slot >= count_) fail(slot, "out of range (" + std::to_string(count_) + " slots)");
  if (pipeline_->slotType(slot) != VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)
    fail(slot, "is not a storage-buffer slot");
  if (!r.buffer || !r.buffer->valid()) fail(slot, "has no buffer");
  const VkDeviceSize bytes = r.bytes();
  const uint64_t limit = pipeline_->context().caps().maxStorageBufferRange;
  if (bytes > limit)
    fail(slot, "buffer '" + r.buffer->name() + "' range of " + std::to_string(bytes >> 20) +
                   " MiB exceeds the device's maxStorageBufferRange of " +
                   std::to_string(limit >> 20) + " MiB");
  buffers_[slot] = {r.buffer->handle(), r.offset, bytes};
  setMask_ |= 1u << slot;
  return *this;
}

Binder& Binder::setTexel(uint32_t slot, VkBufferView view) {
  if (slot >= count_) fail(slot, "out of range (" + std::to_string(count_) + " slots)");
  if (pipeline_->slotType(slot) != VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER)
    fail(slot, "is not a texel-buffer slot");
  if (view == VK_NULL_HANDLE) fail(slot, "has no texel view");
  views_[slot] = view;
  setMask_ |= 1u << slot;
  return *this;
}

void Binder::bindRaw(VkCommandBuffer cmd, const void* push, size_t pushBytes) const {
  std::array<VkWriteDescriptorSet, kMaxSlots> writes;
  for (uint32_t slot = 0; slot < count_; ++slot) {
    if (!(setMask_ >> slot & 1u)) fail(slot, "left unset");
    VkWriteDescriptorSet& w = writes[slot];
    w = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstBinding = slot;
    w.descriptorCount = 1;
    w.descriptorType = pipeline_->slotType(slot);
    if (w.descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)
      w.pBufferInfo = &buffers_[slot];
    else
      w.pTexelBufferView = &views_[slot];
  }
  pipeline_->bindWrites(cmd, std::span<const VkWriteDescriptorSet>(writes.data(), count_), push,
                        pushBytes);
}

}  // namespace osr::vk
