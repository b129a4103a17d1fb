#include "viewer/presenter.h"

#include "common/error.h"
#include "image/image_io.h"
#include "vk/check.h"

namespace osr::viewer {

namespace {

VkRenderPass makeRenderPass(const vk::Context& ctx, VkFormat format) {
  // The film was copied in before the pass (load it); afterwards the image is read back for
  // screenshots or handed to present, so it leaves as a transfer source.
  VkAttachmentDescription color{};
  color.format = format;
  color.samples = VK_SAMPLE_COUNT_1_BIT;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &ref;
  VkSubpassDependency deps[2] = {};
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[0].srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  deps[0].dstAccessMask =
      VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 1;
  info.pAttachments = &color;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 2;
  info.pDependencies = deps;
  VkRenderPass pass = VK_NULL_HANDLE;
  vk::check(vkCreateRenderPass(ctx.device(), &info, nullptr, &pass), "vkCreateRenderPass");
  ctx.setName(VK_OBJECT_TYPE_RENDER_PASS, uint64_t(pass), "viewer panel pass");
  return pass;
}

void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                  VkPipelineStageFlags srcStage, VkAccessFlags srcAccess,
                  VkPipelineStageFlags dstStage, VkAccessFlags dstAccess) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = srcAccess;
  b.dstAccessMask = dstAccess;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

}  // namespace

Presenter::Presenter(const vk::Context& ctx, VkSurfaceKHR surface, VkExtent2D extent)
    : ctx_(ctx), surface_(surface), format_(chooseSurfaceFormat(ctx, surface)) {
  try {
    create(extent);
  } catch (...) {
    release();  // a throwing constructor runs no destructor
    throw;
  }
}

void Presenter::create(VkExtent2D extent) {
  const vk::Context& ctx = ctx_;
  const VkSurfaceKHR surface = surface_;
  renderPass_ = makeRenderPass(ctx, format_.format);
  VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  poolInfo.queueFamilyIndex = ctx.queueFamily();
  vk::check(vkCreateCommandPool(ctx.device(), &poolInfo, nullptr, &pool_), "vkCreateCommandPool");
  swapchain_ =
      std::make_unique<Swapchain>(ctx, surface, format_, renderPass_, extent, VK_NULL_HANDLE);
  for (Slot& s : slots_) {
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    vk::check(vkAllocateCommandBuffers(ctx.device(), &alloc, &s.cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    vk::check(vkCreateFence(ctx.device(), &fence, nullptr, &s.fence), "vkCreateFence");
    VkSemaphoreCreateInfo sem{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    vk::check(vkCreateSemaphore(ctx.device(), &sem, nullptr, &s.imageAcquired),
              "vkCreateSemaphore");
    makeStaging(s);
  }
}

Presenter::~Presenter() {
  release();
}

void Presenter::release() noexcept {
  (void)vkDeviceWaitIdle(ctx_.device());
  for (Retired& r : retired_) r.destroy();
  retired_.clear();
  for (Slot& s : slots_) {
    s.staging.reset();
    if (s.imageAcquired) vkDestroySemaphore(ctx_.device(), s.imageAcquired, nullptr);
    if (s.fence) vkDestroyFence(ctx_.device(), s.fence, nullptr);
    s = Slot{};
  }
  swapchain_.reset();
  if (pool_) vkDestroyCommandPool(ctx_.device(), pool_, nullptr);  // frees the command buffers
  if (renderPass_) vkDestroyRenderPass(ctx_.device(), renderPass_, nullptr);
  pool_ = VK_NULL_HANDLE;
  renderPass_ = VK_NULL_HANDLE;
}

void Presenter::makeStaging(Slot& slot) {
  ++stagingGeneration_;
  const VkExtent2D e = swapchain_->extent();
  slot.staging = std::make_unique<vk::Buffer>(ctx_, VkDeviceSize(e.width) * e.height * 4,
                                              vk::MemoryUse::HostUpload, "viewer frame staging");
}

bool Presenter::frameDone(uint64_t frame) const {
  if (frame == 0) return true;
  const Slot& s = slots_[frame % kFramesInFlight];
  // A slot is reused only after its fence was waited, so a newer frame there means this one
  // completed.
  if (s.frame > frame) return true;
  return s.frame == frame && vkGetFenceStatus(ctx_.device(), s.fence) == VK_SUCCESS;
}

void Presenter::retire(std::function<void()> destroy) {
  retired_.push_back({frame_, std::move(destroy)});
}

void Presenter::collectRetired() {
  for (size_t i = 0; i < retired_.size();) {
    if (frameDone(retired_[i].lastFrame)) {
      retired_[i].destroy();
      retired_.erase(retired_.begin() + long(i));
    } else {
      ++i;
    }
  }
}

void Presenter::resize(VkExtent2D extent) {
  auto next = std::make_unique<Swapchain>(ctx_, surface_, format_, renderPass_, extent,
                                          swapchain_->handle());
  // The old swapchain, its framebuffers and semaphores, and the staging buffers sized for it
  // may still be read by frames in flight: destroy them when those frames are done.
  std::shared_ptr<Swapchain> old(std::move(swapchain_));
  retire([old]() mutable { old.reset(); });
  swapchain_ = std::move(next);
  for (Slot& s : slots_) {
    std::shared_ptr<vk::Buffer> staging(std::move(s.staging));
    retire([staging]() mutable { staging.reset(); });
    makeStaging(s);
  }
}

uint8_t* Presenter::beginFrame() {
  slot_ = uint32_t((frame_ + 1) % kFramesInFlight);
  Slot& s = slots_[slot_];
  vk::check(vkWaitForFences(ctx_.device(), 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  collectRetired();
  VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_->handle(), UINT64_MAX,
                                     s.imageAcquired, VK_NULL_HANDLE, &image_);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) return nullptr;
  if (r != VK_SUBOPTIMAL_KHR) vk::check(r, "vkAcquireNextImageKHR");
  return static_cast<uint8_t*>(s.staging->mapped());
}

bool Presenter::endFrame(const std::function<void(VkCommandBuffer)>& drawPanel,
                         const std::string& screenshotPng) {
  Slot& s = slots_[slot_];
  const VkExtent2D e = swapchain_->extent();
  const VkImage image = swapchain_->image(image_);
  std::unique_ptr<vk::Buffer> readback;
  if (!screenshotPng.empty())
    readback = std::make_unique<vk::Buffer>(ctx_, VkDeviceSize(e.width) * e.height * 4,
                                            vk::MemoryUse::HostReadback, "viewer screenshot");

  vk::check(vkResetCommandBuffer(s.cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vk::check(vkBeginCommandBuffer(s.cmd, &begin), "vkBeginCommandBuffer");
  ctx_.beginLabel(s.cmd, "viewer frame");
  // The acquire semaphore is waited at the transfer stage, so the layout change chains on it.
  imageBarrier(s.cmd, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
               VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_WRITE_BIT);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {e.width, e.height, 1};
  vkCmdCopyBufferToImage(s.cmd, s.staging->handle(), image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                         &region);
  imageBarrier(s.cmd, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
               VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = renderPass_;
  rp.framebuffer = swapchain_->framebuffer(image_);
  rp.renderArea = {{0, 0}, e};
  vkCmdBeginRenderPass(s.cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
  drawPanel(s.cmd);
  vkCmdEndRenderPass(s.cmd);
  if (readback) {
    VkBufferImageCopy back = region;
    vkCmdCopyImageToBuffer(s.cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback->handle(),
                           1, &back);
    VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(s.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                         &host, 0, nullptr, 0, nullptr);
  }
  imageBarrier(s.cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
               VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT,
               VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0);
  ctx_.endLabel(s.cmd);
  vk::check(vkEndCommandBuffer(s.cmd), "vkEndCommandBuffer");

  vk::check(vkResetFences(ctx_.device(), 1, &s.fence), "vkResetFences");
  const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  const VkSemaphore finished = swapchain_->renderFinished(image_);
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &s.imageAcquired;
  submit.pWaitDstStageMask = &waitStage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &s.cmd;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = &finished;
  vk::check(vkQueueSubmit(ctx_.queue(), 1, &submit, s.fence), "vkQueueSubmit");
  s.frame = ++frame_;

  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &finished;
  present.swapchainCount = 1;
  const VkSwapchainKHR handle = swapchain_->handle();
  present.pSwapchains = &handle;
  present.pImageIndices = &image_;
  const VkResult r = vkQueuePresentKHR(ctx_.queue(), &present);
  if (readback) {
    vk::check(vkWaitForFences(ctx_.device(), 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    writeScreenshot(screenshotPng, *readback);
  }
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return false;
  vk::check(r, "vkQueuePresentKHR");
  return true;
}

void Presenter::writeScreenshot(const std::string& path, const vk::Buffer& readback) const {
  const VkExtent2D e = swapchain_->extent();
  const auto* px = static_cast<const uint8_t*>(readback.mapped());
  std::vector<uint8_t> rgb(size_t(e.width) * e.height * 3);
  const bool swap = bgra();
  for (size_t i = 0; i < size_t(e.width) * e.height; ++i) {
    rgb[3 * i + 0] = px[4 * i + (swap ? 2 : 0)];
    rgb[3 * i + 1] = px[4 * i + 1];
    rgb[3 * i + 2] = px[4 * i + (swap ? 0 : 2)];
  }
  image::writePng8(path, int(e.width), int(e.height), rgb);
}

}  // namespace osr::viewer
