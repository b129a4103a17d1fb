// Dear ImGui (Debian's libimgui-dev 1.86, whose static library carries the GLFW and Vulkan
// backends) set up on the viewer's window and render pass: one context, fonts uploaded once,
// its own descriptor pool. Constructed after the Presenter, destroyed before it.
#pragma once
#include <vulkan/vulkan.h>

#include "viewer/presenter.h"
#include "viewer/window.h"
#include "vk/context.h"

namespace osr::viewer {

class ImGuiLayer {
 public:
  // Installs GLFW callbacks that chain to any the viewer installed before.
  ImGuiLayer(const vk::Context& ctx, Window& window, const Presenter& presenter);
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  // Starts a UI frame (between beginFrame and the ImGui:: calls).
  void newFrame();
  // Records the frame's draw lists into `cmd` (inside the presenter's render pass).
  void render(VkCommandBuffer cmd);

 private:
  const vk::Context& ctx_;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  bool glfwInit_ = false, vulkanInit_ = false;
};

}  // namespace osr::viewer
