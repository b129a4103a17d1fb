// The viewer's GLFW window and its Vulkan surface. GLFW is initialised only here, so offline
// renders never touch a window system.
#pragma once
#include <vulkan/vulkan.h>

#include <string>
#include <vector>

struct GLFWwindow;

namespace osr::viewer {

// Throws InputError (exit 2) with one line suggesting --offline when there is no display to
// open a window on: DISPLAY and WAYLAND_DISPLAY unset, or GLFW cannot connect or lacks Vulkan.
// Returns the instance extensions the surface needs (for vk::ContextOptions).
std::vector<std::string> requireDisplay();

class Window {
 public:
  // requireDisplay() must have succeeded. The window is not resizable below 64 x 64.
  Window(int width, int height, const std::string& title);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  GLFWwindow* handle() const { return window_; }
  // The surface on `instance` (created once; destroyed by the destructor, before the caller
  // destroys the instance). Throws InputError when `physicalDevice`'s queue `family` cannot
  // present to it.
  VkSurfaceKHR createSurface(VkInstance instance, VkPhysicalDevice physicalDevice, uint32_t family);
  // Framebuffer size in pixels (0 x 0 while minimised).
  void framebufferSize(int& width, int& height) const;
  // Asks the window system for a new size (the scripted resize); the framebuffer follows.
  void resize(int width, int height);
  bool shouldClose() const;

 private:
  GLFWwindow* window_ = nullptr;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
};

}  // namespace osr::viewer
