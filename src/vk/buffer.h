// A VkBuffer with its own memory. Device-local buffers are filled through a staging copy where
// the device has separate memory and mapped directly where it is unified (lavapipe, iGPUs).
#pragma once
#include <vulkan/vulkan.h>

#include <string>
#include <vector>

#include "vk/context.h"

namespace osr::vk {

enum class MemoryUse {
  DeviceLocal,  // kernels read and write it; host access goes through upload()/download()
  HostUpload,   // host writes every frame (mapped, coherent)
  HostReadback  // host reads results (mapped, cached where possible)
};

class Buffer {
 public:
  Buffer() = default;
  // size > 0. `name` labels the buffer in validation messages and error text. Throws
  // DeviceError naming the size and the limit when size exceeds maxMemoryAllocationSize.
  Buffer(const Context& ctx, VkDeviceSize size, MemoryUse use, std::string name,
         VkBufferUsageFlags extraUsage = 0);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  const std::string& name() const { return name_; }
  // The usage it was made with (storage, transfer, indirect, and the extra usage asked for).
  VkBufferUsageFlags usage() const { return usage_; }
  bool valid() const { return buffer_ != VK_NULL_HANDLE; }
  // Its address for GL_EXT_buffer_reference (caps().bufferDeviceAddress must be true).
  VkDeviceAddress deviceAddress() const;
  // Mapped pointer, or nullptr when the memory is not host-visible.
  void* mapped() const { return mapped_; }

  // On a CPU device, makes [0, bytes) resident now (MADV_POPULATE_WRITE), so that the kernels
  // that first write it do not stall on page faults; elsewhere nothing.
  void prefault(VkDeviceSize bytes) const;

  // Copies host data into [offset, offset + bytes); waits for completion.
  void upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
  // Copies [offset, offset + bytes) to host memory; waits for completion.
  void download(void* data, VkDeviceSize bytes, VkDeviceSize offset = 0) const;

  template <class T>
  void uploadVector(const std::vector<T>& v, VkDeviceSize offset = 0) {
    if (!v.empty()) upload(v.data(), v.size() * sizeof(T), offset);
  }
  template <class T>
  std::vector<T> downloadVector(size_t count, VkDeviceSize offset = 0) const {
    std::vector<T> v(count);
    if (count) download(v.data(), count * sizeof(T), offset);
    return v;
  }

 private:
  void release();
  const Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
  bool coherent_ = true;
  VkBufferUsageFlags usage_ = 0;
  std::string name_;
};

// A byte range of a buffer bound to one storage-buffer slot of a pass.
struct BufferRange {
  const Buffer* buffer = nullptr;
  VkDeviceSize offset = 0;
  VkDeviceSize size = VK_WHOLE_SIZE;  // to the end of the buffer
  BufferRange() = default;
  BufferRange(const Buffer& b) : buffer(&b) {}  // NOLINT: a whole buffer converts implicitly
  BufferRange(const Buffer& b, VkDeviceSize off, VkDeviceSize bytes)
      : buffer(&b), offset(off), size(bytes) {}
  VkDeviceSize bytes() const;
};

// Full execution + memory dependency between compute/transfer work recorded before and after.
void computeBarrier(VkCommandBuffer cmd);
// Makes transfer writes (vkCmdFillBuffer/CopyBuffer) visible to compute, and compute writes
// visible to later transfers: the same as computeBarrier, named for the reader.
inline void transferBarrier(VkCommandBuffer cmd) { computeBarrier(cmd); }

}  // namespace osr::vk
