// A typed view of a buffer range (VkBufferView), for texel-buffer bindings: on CPU Vulkan a
// texel fetch is a straight-line gather, much cheaper than a per-lane storage-buffer load.
#pragma once
#include <vulkan/vulkan.h>

#include <string>

#include "vk/buffer.h"

namespace osr::vk {

class BufferView {
 public:
  BufferView() = default;
  // `range` must be aligned to minTexelBufferOffsetAlignment and hold whole texels.
  BufferView(const Context& ctx, const BufferRange& range, VkFormat format, const std::string& name);
  ~BufferView();
  BufferView(BufferView&& other) noexcept;
  BufferView& operator=(BufferView&& other) noexcept;
  BufferView(const BufferView&) = delete;
  BufferView& operator=(const BufferView&) = delete;
  VkBufferView handle() const { return view_; }

  // An RGBA32UI view of `buffer` from offset 0 (whole 16-byte texels), cut at the device's
  // maxTexelBufferElements; `covers` (optional) says whether it reaches the buffer's end.
  static BufferView uintTexels(const Context& ctx, const Buffer& buffer, const std::string& name,
                               bool* covers = nullptr);
  // An R32UI view of `buffer` from offset 0 (whole 4-byte words), cut likewise.
  static BufferView uintWords(const Context& ctx, const Buffer& buffer, const std::string& name,
                              bool* covers = nullptr);

 private:
  const Context* ctx_ = nullptr;
  VkBufferView view_ = VK_NULL_HANDLE;
};

}  // namespace osr::vk
