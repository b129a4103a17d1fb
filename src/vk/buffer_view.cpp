#include "vk/buffer_view.h"

#include <algorithm>
#include <utility>

#include "vk/check.h"

namespace osr::vk {

BufferView::BufferView(const Context& ctx, const BufferRange& range, VkFormat format,
                       const std::string& name)
    : ctx_(&ctx) {
  VkBufferViewCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  info.buffer = range.buffer->handle();
  info.format = format;
  info.offset = range.offset;
  info.range = range.bytes();
  check(vkCreateBufferView(ctx.device(), &info, nullptr, &view_), name.c_str());
  ctx.setName(VK_OBJECT_TYPE_BUFFER_VIEW, reinterpret_cast<uint64_t>(view_), name);
}

namespace {
BufferView wholeTexels(const Context& ctx, const Buffer& buffer, const std::string& name, bool* covers,
                       VkDeviceSize texelBytes, VkFormat format) {
  VkDeviceSize texels = buffer.size() / texelBytes;
  VkDeviceSize maxTexels = ctx.caps().maxTexelBufferElements;
  if (covers) *covers = texels <= maxTexels;
  return BufferView(ctx, BufferRange(buffer, 0, std::min(texels, maxTexels) * texelBytes), format, name);
}
}  // namespace

BufferView BufferView::uintTexels(const Context& ctx, const Buffer& buffer,
                                  const std::string& name, bool* covers) {
  return wholeTexels(ctx, buffer, name, covers, 16, VK_FORMAT_R32G32B32A32_UINT);
}

BufferView BufferView::uintWords(const Context& ctx, const Buffer& buffer, const std::string& name,
                                 bool* covers) {
  return wholeTexels(ctx, buffer, name, covers, 4, VK_FORMAT_R32_UINT);
}

BufferView::~BufferView() {
  if (view_) vkDestroyBufferView(ctx_->device(), view_, nullptr);
}

BufferView::BufferView(BufferView&& o) noexcept { *this = std::move(o); }

BufferView& BufferView::operator=(BufferView&& o) noexcept {
  if (this != &o) {
    if (view_) vkDestroyBufferView(ctx_->device(), view_, nullptr);
    ctx_ = o.ctx_;
    view_ = o.view_;
    o.view_ = VK_NULL_HANDLE;
  }
  return *this;
}

}  // namespace osr::vk
