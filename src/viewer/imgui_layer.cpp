#include "viewer/imgui_layer.h"

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>
#include <imgui.h>

#include "vk/check.h"

namespace osr::viewer {

namespace {
void checkImGuiVk(VkResult r) {
  vk::check(r, "ImGui Vulkan backend");
}
}  // namespace

ImGuiLayer::ImGuiLayer(const vk::Context& ctx, Window& window, const Presenter& presenter)
    : ctx_(ctx) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini dropped into the user's directory
  ImGui::StyleColorsDark();
  // Compact: the whole panel fits beside a 512-pixel-high image.
  ImGuiStyle& style = ImGui::GetStyle();
  style.ItemSpacing = ImVec2(6.f, 3.f);
  style.FramePadding = ImVec2(4.f, 2.f);
  style.WindowPadding = ImVec2(6.f, 6.f);
  try {
    // The font atlas is the only descriptor set the backend allocates.
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 4};
    VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    poolInfo.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    poolInfo.maxSets = 4;
    poolInfo.poolSizeCount = 1;
    poolInfo.pPoolSizes = &size;
    vk::check(vkCreateDescriptorPool(ctx.device(), &poolInfo, nullptr, &pool_),
              "vkCreateDescriptorPool");
    glfwInit_ = ImGui_ImplGlfw_InitForVulkan(window.handle(), true);
    ImGui_ImplVulkan_InitInfo info{};
    info.Instance = ctx.instance();
    info.PhysicalDevice = ctx.physicalDevice();
    info.Device = ctx.device();
    info.QueueFamily = ctx.queueFamily();
    info.Queue = ctx.queue();
    info.DescriptorPool = pool_;
    info.MinImageCount = 2;
    // The backend rotates its vertex buffers over ImageCount frames: at least the frames
    // that may be in flight.
    info.ImageCount = std::max(presenter.imageCount(), Presenter::kFramesInFlight);
    info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    info.CheckVkResultFn = checkImGuiVk;
    vulkanInit_ = ImGui_ImplVulkan_Init(&info, presenter.renderPass());
    ctx.submitAndWait([](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
    ImGui_ImplVulkan_DestroyFontUploadObjects();
  } catch (...) {
    this->~ImGuiLayer();
    throw;
  }
}

ImGuiLayer::~ImGuiLayer() {
  if (ctx_.device()) (void)vkDeviceWaitIdle(ctx_.device());
  if (vulkanInit_) ImGui_ImplVulkan_Shutdown();
  if (glfwInit_) ImGui_ImplGlfw_Shutdown();
  vulkanInit_ = glfwInit_ = false;
  if (ImGui::GetCurrentContext()) ImGui::DestroyContext();
  if (pool_) vkDestroyDescriptorPool(ctx_.device(), pool_, nullptr);
  pool_ = VK_NULL_HANDLE;
}

void ImGuiLayer::newFrame() {
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
}

void ImGuiLayer::render(VkCommandBuffer cmd) {
  ImGui::Render();
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd);
}

}  // namespace osr::viewer
