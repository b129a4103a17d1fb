// Puts frames on the window: per frame, the host-drawn image (film already tone mapped, panel
// area blank) is copied into the acquired swapchain image, the ImGui panel is drawn over it in
// one render pass, and the image is presented. kFramesInFlight frames overlap, each with its
// own command buffer, fence, acquire semaphore and staging buffer. Resizing makes a new
// swapchain and staging buffers; the old ones go to a retire list and are destroyed once every
// frame that used them has completed, never while a command buffer may still read them.
#pragma once
#include <vulkan/vulkan.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "viewer/swapchain.h"
#include "vk/buffer.h"
#include "vk/context.h"

namespace osr::viewer {

class Presenter {
 public:
  static constexpr uint32_t kFramesInFlight = 2;

  Presenter(const vk::Context& ctx, VkSurfaceKHR surface, VkExtent2D extent);
  ~Presenter();  // waits for the device, then frees everything
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  VkRenderPass renderPass() const { return renderPass_; }
  VkExtent2D extent() const { return swapchain_->extent(); }
  uint32_t imageCount() const { return swapchain_->imageCount(); }
  bool bgra() const { return format_.format == VK_FORMAT_B8G8R8A8_UNORM; }

  // Recreates the swapchain for `extent` (the old one is retired, not destroyed).
  void resize(VkExtent2D extent);

  // Starts a frame: waits for its slot, frees retired objects that are no longer in use and
  // acquires an image. Returns the slot's staging pixels (extent().width x height, 4 bytes per
  // pixel in the swapchain's channel order, row-major), or nullptr when the swapchain is out
  // of date (the caller resizes and tries again).
  uint8_t* beginFrame();
  // The frame slot beginFrame() chose (its staging pixels persist between its frames, so a
  // caller may skip rewriting what has not changed) and a number that changes whenever the
  // staging buffers are remade.
  uint32_t slot() const { return slot_; }
  uint64_t stagingGeneration() const { return stagingGeneration_; }
  // Records the copy of the staging pixels, then `drawPanel(cmd)` inside the render pass,
  // submits and presents. With a non-empty `screenshotPng`, also copies the finished image
  // back, waits for it and writes it as a PNG (what the window shows, panel included).
  // Returns false when the swapchain needs a resize.
  bool endFrame(const std::function<void(VkCommandBuffer)>& drawPanel,
                const std::string& screenshotPng = {});

 private:
  struct Slot {
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkSemaphore imageAcquired = VK_NULL_HANDLE;
    std::unique_ptr<vk::Buffer> staging;
    uint64_t frame = 0;  // number of the last frame submitted from this slot (0: none)
  };
  struct Retired {
    uint64_t lastFrame;  // the last frame that may use it
    std::function<void()> destroy;
  };
  void create(VkExtent2D extent);
  void release() noexcept;
  bool frameDone(uint64_t frame) const;
  void retire(std::function<void()> destroy);
  void collectRetired();
  void makeStaging(Slot& slot);
  void writeScreenshot(const std::string& path, const vk::Buffer& readback) const;

  const vk::Context& ctx_;
  VkSurfaceKHR surface_;
  VkSurfaceFormatKHR format_;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::unique_ptr<Swapchain> swapchain_;
  Slot slots_[kFramesInFlight];
  std::vector<Retired> retired_;
  uint64_t frame_ = 0;  // frames submitted so far
  uint32_t slot_ = 0;   // slot of the frame being drawn
  uint64_t stagingGeneration_ = 0;
  uint32_t image_ = 0;  // its swapchain image
};

}  // namespace osr::viewer
