#include "viewer/window.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <cstdlib>

#include "common/error.h"
#include "vk/check.h"

namespace osr::viewer {

namespace {
constexpr const char* kUseOffline = "; render without a window with --offline out.exr";

bool envSet(const char* name) {
  const char* v = std::getenv(name);
  return v && *v;
}

// GLFW reports errors through a callback; keep the last one for the exception text.
std::string gLastGlfwError;
void onGlfwError(int, const char* text) {
  gLastGlfwError = text ? text : "";
}
}  // namespace

std::vector<std::string> requireDisplay() {
  if (!envSet("DISPLAY") && !envSet("WAYLAND_DISPLAY"))
    throw InputError(std::string("viewer: no display (DISPLAY and WAYLAND_DISPLAY are unset)") +
                     kUseOffline);
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit())
    throw InputError("viewer: cannot open the display (" + gLastGlfwError + ")" + kUseOffline);
  if (!glfwVulkanSupported())
    throw InputError(std::string("viewer: the window system has no Vulkan presentation") +
                     kUseOffline);
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  std::vector<std::string> out;
  for (uint32_t i = 0; i < count; ++i) out.push_back(names[i]);
  return out;
}

Window::Window(int width, int height, const std::string& title) {
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_)
    throw InputError("viewer: cannot create a window (" + gLastGlfwError + ")" + kUseOffline);
  glfwSetWindowSizeLimits(window_, 64, 64, GLFW_DONT_CARE, GLFW_DONT_CARE);
}

Window::~Window() {
  if (surface_) vkDestroySurfaceKHR(instance_, surface_, nullptr);
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

VkSurfaceKHR Window::createSurface(VkInstance instance, VkPhysicalDevice physicalDevice,
                                   uint32_t family) {
  instance_ = instance;
  vk::check(glfwCreateWindowSurface(instance, window_, nullptr, &surface_),
            "glfwCreateWindowSurface");
  VkBool32 supported = VK_FALSE;
  vk::check(vkGetPhysicalDeviceSurfaceSupportKHR(physicalDevice, family, surface_, &supported),
            "vkGetPhysicalDeviceSurfaceSupportKHR");
  if (!supported)
    throw InputError(std::string("viewer: the Vulkan device's queue cannot present to this "
                                 "window") +
                     kUseOffline);
  return surface_;
}

void Window::framebufferSize(int& width, int& height) const {
  glfwGetFramebufferSize(window_, &width, &height);
}

void Window::resize(int width, int height) {
  glfwSetWindowSize(window_, width, height);
}

bool Window::shouldClose() const {
  return glfwWindowShouldClose(window_);
}

}  // namespace osr::viewer
