// One VkSwapchainKHR with what hangs off its images: views, framebuffers for the panel's render
// pass, and a "render finished" semaphore per image (a present may still wait on an image's
// semaphore when the next frame starts, so they cannot be per frame in flight). A resize makes
// a new Swapchain from the old one; the presenter destroys the old one only after the frames
// that used it have completed.
#pragma once
#include <vulkan/vulkan.h>

#include <vector>

#include "vk/context.h"

namespace osr::viewer {

// The surface format the viewer draws in: 8-bit UNORM, B8G8R8A8 or R8G8B8A8. The film arrives
// already sRGB-encoded (image::toneMapSrgb8, as in the PNG), and ImGui expects a non-sRGB target.
VkSurfaceFormatKHR chooseSurfaceFormat(const vk::Context& ctx, VkSurfaceKHR surface);

class Swapchain {
 public:
  // `extent` is the framebuffer size wanted (the surface's current extent wins where it has
  // one). `old` (may be null) is handed to the driver for reuse; the caller keeps it alive.
  Swapchain(const vk::Context& ctx, VkSurfaceKHR surface, VkSurfaceFormatKHR format,
            VkRenderPass renderPass, VkExtent2D extent, VkSwapchainKHR old);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  VkSwapchainKHR handle() const { return swapchain_; }
  VkExtent2D extent() const { return extent_; }
  uint32_t imageCount() const { return uint32_t(images_.size()); }
  VkImage image(uint32_t i) const { return images_[i]; }
  VkFramebuffer framebuffer(uint32_t i) const { return framebuffers_[i]; }
  VkSemaphore renderFinished(uint32_t i) const { return renderFinished_[i]; }

 private:
  void release() noexcept;
  const vk::Context& ctx_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkExtent2D extent_{};
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  std::vector<VkSemaphore> renderFinished_;
};

}  // namespace osr::viewer
