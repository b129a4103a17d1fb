#include "viewer/swapchain.h"

#include <algorithm>
#include <string>

#include "common/error.h"
#include "vk/check.h"

namespace osr::viewer {

VkSurfaceFormatKHR chooseSurfaceFormat(const vk::Context& ctx, VkSurfaceKHR surface) {
  uint32_t count = 0;
  vk::check(vkGetPhysicalDeviceSurfaceFormatsKHR(ctx.physicalDevice(), surface, &count, nullptr),
            "vkGetPhysicalDeviceSurfaceFormatsKHR");
  std::vector<VkSurfaceFormatKHR> formats(count);
  vk::check(
      vkGetPhysicalDeviceSurfaceFormatsKHR(ctx.physicalDevice(), surface, &count, formats.data()),
      "vkGetPhysicalDeviceSurfaceFormatsKHR");
  for (VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == want && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
  throw InputError(
      "viewer: the window offers no 8-bit BGRA/RGBA UNORM surface format; use "
      "--offline out.exr");
}

Swapchain::Swapchain(const vk::Context& ctx, VkSurfaceKHR surface, VkSurfaceFormatKHR format,
                     VkRenderPass renderPass, VkExtent2D extent, VkSwapchainKHR old)
    : ctx_(ctx) {
  try {
    VkSurfaceCapabilitiesKHR caps;
    vk::check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx.physicalDevice(), surface, &caps),
              "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                    VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                    VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    if ((caps.supportedUsageFlags & usage) != usage)
      throw DeviceError("viewer: swapchain images cannot be copied to and from");
    extent_ = caps.currentExtent.width != 0xFFFFFFFFu ? caps.currentExtent : extent;
    extent_.width = std::clamp(extent_.width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height =
        std::clamp(extent_.height, caps.minImageExtent.height, caps.maxImageExtent.height);
    uint32_t images = caps.minImageCount + 1;
    if (caps.maxImageCount) images = std::min(images, caps.maxImageCount);

    VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    info.surface = surface;
    info.minImageCount = images;
    info.imageFormat = format.format;
    info.imageColorSpace = format.colorSpace;
    info.imageExtent = extent_;
    info.imageArrayLayers = 1;
    info.imageUsage = usage;
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always supported; paces the UI to the display
    info.clipped = VK_TRUE;
    info.oldSwapchain = old;
    vk::check(vkCreateSwapchainKHR(ctx.device(), &info, nullptr, &swapchain_),
              "vkCreateSwapchainKHR");
    ctx.setName(VK_OBJECT_TYPE_SWAPCHAIN_KHR, uint64_t(swapchain_), "viewer swapchain");

    uint32_t count = 0;
    vk::check(vkGetSwapchainImagesKHR(ctx.device(), swapchain_, &count, nullptr),
              "vkGetSwapchainImagesKHR");
    images_.resize(count);
    vk::check(vkGetSwapchainImagesKHR(ctx.device(), swapchain_, &count, images_.data()),
              "vkGetSwapchainImagesKHR");
    for (uint32_t i = 0; i < count; ++i) {
      VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      view.image = images_[i];
      view.viewType = VK_IMAGE_VIEW_TYPE_2D;
      view.format = format.format;
      view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
      views_.push_back(VK_NULL_HANDLE);
      vk::check(vkCreateImageView(ctx.device(), &view, nullptr, &views_.back()),
                "vkCreateImageView");
      VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
      fb.renderPass = renderPass;
      fb.attachmentCount = 1;
      fb.pAttachments = &views_.back();
      fb.width = extent_.width;
      fb.height = extent_.height;
      fb.layers = 1;
      framebuffers_.push_back(VK_NULL_HANDLE);
      vk::check(vkCreateFramebuffer(ctx.device(), &fb, nullptr, &framebuffers_.back()),
                "vkCreateFramebuffer");
      VkSemaphoreCreateInfo sem{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      renderFinished_.push_back(VK_NULL_HANDLE);
      vk::check(vkCreateSemaphore(ctx.device(), &sem, nullptr, &renderFinished_.back()),
                "vkCreateSemaphore");
      const std::string n = "viewer swapchain image " + std::to_string(i);
      ctx.setName(VK_OBJECT_TYPE_IMAGE, uint64_t(images_[i]), n);
      ctx.setName(VK_OBJECT_TYPE_SEMAPHORE, uint64_t(renderFinished_[i]), n + " finished");
    }
  } catch (...) {
    release();
    throw;
  }
}

Swapchain::~Swapchain() {
  release();
}

void Swapchain::release() noexcept {
  for (VkSemaphore s : renderFinished_) vkDestroySemaphore(ctx_.device(), s, nullptr);
  for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(ctx_.device(), f, nullptr);
  for (VkImageView v : views_) vkDestroyImageView(ctx_.device(), v, nullptr);
  if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
  renderFinished_.clear();
  framebuffers_.clear();
  views_.clear();
  swapchain_ = VK_NULL_HANDLE;
}

}  // namespace osr::viewer
