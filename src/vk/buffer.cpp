#include "vk/buffer.h"

#include <cstring>

#ifdef __linux__
#include <sys/mman.h>
#endif

#include "common/error.h"
#include "vk/check.h"

namespace osr::vk {

namespace {
// On a CPU device the memory is process memory, and a fresh allocation costs a page fault per
// 4 KiB on first touch, more than the GPU BVH build's own work on a large scene
// (docs/device_notes.md, "What lavapipe charges for"). Transparent huge pages (where
// the system offers them on request: /sys/kernel/mm/transparent_hugepage/enabled = madvise)
// fault 2 MiB at a time. Only the whole 2 MiB pages inside the allocation are advised, and
// only in allocations up to kHugePagesUpTo: where the kernel has no free 2 MiB block it
// compacts memory first, which made a fresh huge page cost 0.3 to 10 s per GiB on the bench VM
// against 0.7 to 2.6 for 4 KiB pages, and the 4K film and accumulation buffers (760 and 930
// MiB) took 7 to 17 s to clear instead of about 1 (docs/device_notes.md).
constexpr VkDeviceSize kHugePagesUpTo = VkDeviceSize(256) << 20;

void adviseHugePages(void* data, VkDeviceSize bytes) {
#ifdef __linux__
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // advice only: failure is harmless
#else
  (void)data;
  (void)bytes;
#endif
}
}  // namespace

Buffer::Buffer(const Context& ctx, VkDeviceSize size, MemoryUse use, std::string name,
               VkBufferUsageFlags extraUsage)
    : Buffer() {
  // Delegating to the default constructor completes the object before this body runs, so a
  // throw below runs ~Buffer and frees the buffer and memory made so far.
  ctx_ = &ctx;
  size_ = size;
  name_ = std::move(name);
  if (size == 0) throw DeviceError("vulkan: buffer '" + name_ + "' has size 0");
  if (size > ctx.caps().maxMemoryAllocationSize)
    throw DeviceError("vulkan: buffer '" + name_ + "' needs " + std::to_string((size + (1 << 20) - 1) >> 20) +
                      " MiB, more than the device's maxMemoryAllocationSize of " +
                      std::to_string(ctx.caps().maxMemoryAllocationSize >> 20) + " MiB (" +
                      ctx.caps().deviceName + ")");
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | extraUsage;
  if (ctx.caps().bufferDeviceAddress) info.usage |= VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  usage_ = info.usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(ctx.device(), &info, nullptr, &buffer_), ("vkCreateBuffer " + name_).c_str());
  ctx.setName(VK_OBJECT_TYPE_BUFFER, reinterpret_cast<uint64_t>(buffer_), name_);

  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx.device(), buffer_, &req);
  constexpr VkMemoryPropertyFlags kHost =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VkMemoryPropertyFlags flags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  switch (use) {
    case MemoryUse::DeviceLocal:
      // On unified memory keep it mappable, so uploads need no staging copy.
      if (ctx.caps().unifiedMemory && ctx.hasMemoryType(req.memoryTypeBits, flags | kHost))
        flags |= kHost;
      break;
    case MemoryUse::HostUpload:
      flags = kHost;
      break;
    case MemoryUse::HostReadback:
      flags = ctx.hasMemoryType(req.memoryTypeBits, kHost | VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                  ? kHost | VK_MEMORY_PROPERTY_HOST_CACHED_BIT
                  : kHost;
      break;
  }
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, flags);
  VkMemoryAllocateFlagsInfo allocFlags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  allocFlags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  if (ctx.caps().bufferDeviceAddress) alloc.pNext = &allocFlags;
  VkResult r = vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_);
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
    throw DeviceError("vulkan: out of memory allocating buffer '" + name_ + "' (" +
                      std::to_string(size >> 20) + " MiB)");
  check(r, ("vkAllocateMemory " + name_).c_str());
  check(vkBindBufferMemory(ctx.device(), buffer_, memory_, 0), "vkBindBufferMemory");
  if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
    check(vkMapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
  if (ctx.caps().isCpu() && mapped_ && req.size <= kHugePagesUpTo) adviseHugePages(mapped_, req.size);
}

void Buffer::prefault(VkDeviceSize bytes) const {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  if (!ctx_->caps().isCpu() || !mapped_ || bytes == 0) return;
  constexpr uintptr_t kPage = 4096;
  uintptr_t begin = reinterpret_cast<uintptr_t>(mapped_) & ~(kPage - 1);
  uintptr_t end = reinterpret_cast<uintptr_t>(mapped_) + std::min(bytes, size_);
  madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);  // advice only
#else
  (void)bytes;
#endif
}

Buffer::~Buffer() { release(); }

Buffer::Buffer(Buffer&& o) noexcept { *this = std::move(o); }

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    release();
    ctx_ = o.ctx_;
    buffer_ = o.buffer_;
    memory_ = o.memory_;
    size_ = o.size_;
    mapped_ = o.mapped_;
    coherent_ = o.coherent_;
    usage_ = o.usage_;
    name_ = std::move(o.name_);
    o.buffer_ = VK_NULL_HANDLE;
    o.memory_ = VK_NULL_HANDLE;
    o.mapped_ = nullptr;
    o.size_ = 0;
  }
  return *this;
}

void Buffer::release() {
  if (!ctx_) return;
  if (buffer_) vkDestroyBuffer(ctx_->device(), buffer_, nullptr);
  if (memory_) vkFreeMemory(ctx_->device(), memory_, nullptr);
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

VkDeviceAddress Buffer::deviceAddress() const {
  if (!ctx_->caps().bufferDeviceAddress)
    throw DeviceError("vulkan: device \"" + ctx_->caps().deviceName +
                      "\" lacks bufferDeviceAddress (buffer '" + name_ + "')");
  VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  info.buffer = buffer_;
  return vkGetBufferDeviceAddress(ctx_->device(), &info);
}

void Buffer::upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  if (offset + bytes > size_)
    throw DeviceError("vulkan: upload of " + std::to_string(bytes) + " bytes at " +
                      std::to_string(offset) + " overruns buffer '" + name_ + "'");
  if (bytes == 0) return;
  if (mapped_) {
    // Callers upload between submissions, so no command may still be reading this memory.
    std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, MemoryUse::HostUpload, name_ + " staging");
  std::memcpy(staging.mapped(), data, bytes);
  ctx_->submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, offset, bytes};
    vkCmdCopyBuffer(cmd, staging.handle(), buffer_, 1, &region);
  });
}

void Buffer::download(void* data, VkDeviceSize bytes, VkDeviceSize offset) const {
  if (offset + bytes > size_)
    throw DeviceError("vulkan: download of " + std::to_string(bytes) + " bytes at " +
                      std::to_string(offset) + " overruns buffer '" + name_ + "'");
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, MemoryUse::HostReadback, name_ + " readback");
  ctx_->submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{offset, 0, bytes};
    vkCmdCopyBuffer(cmd, buffer_, staging.handle(), 1, &region);
  });
  std::memcpy(data, staging.mapped(), bytes);
}

VkDeviceSize BufferRange::bytes() const {
  return size == VK_WHOLE_SIZE ? buffer->size() - offset : size;
}

void computeBarrier(VkCommandBuffer cmd) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                          VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  constexpr VkPipelineStageFlags kStages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                                           VK_PIPELINE_STAGE_TRANSFER_BIT;
  vkCmdPipelineBarrier(cmd, kStages, kStages | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, 0, 1,
                       &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace osr::vk
