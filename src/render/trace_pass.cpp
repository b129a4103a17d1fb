#include "render/trace_pass.h"

#include <algorithm>
#include <vector>

namespace osr::render {

namespace pt = gpu::pt;

static_assert(pt::kPtSceneBinding == pt::kPtBvhBinding + gpu::bvh::kBvhBindingCount);
static_assert(pt::kPtSceneTexelBinding == pt::kPtSceneBinding + gpu::scene::kSceneBindingCount);
static_assert(pt::kPtBindingCount ==
              pt::kPtSceneTexelBinding + gpu::scene::kSceneTexelBindingCount);

namespace {
std::vector<VkDescriptorType> descriptorTypes() {
  std::vector<VkDescriptorType> types(pt::kPtBindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  auto bvhTypes = bvh::Bvh::descriptorTypes();
  std::copy(bvhTypes.begin(), bvhTypes.end(), types.begin() + pt::kPtBvhBinding);
  std::fill(types.begin() + pt::kPtSceneTexelBinding, types.end(),
            VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER);
  return types;
}
}  // namespace

TracePass::TracePass(const vk::Context& ctx, uint32_t integrator, uint32_t sceneFeatures,
                     bool sceneTexelFetch)
    : pipeline_(ctx, shaders::Id::pt_trace, descriptorTypes(), sizeof(pt::Push),
                {vk::specUint(pt::kPtSpecIntegrator, integrator),
                 vk::specUint(pt::kPtSpecSceneFeatures, sceneFeatures), bvh::traversalSpec(ctx),
                 vk::specUint(gpu::scene::kSceneSpecTexelFetch, sceneTexelFetch ? 1u : 0u)}) {}

void TracePass::record(VkCommandBuffer cmd, const Args& a) const {
  std::vector<vk::ComputePipeline::Descriptor> slots = {vk::BufferRange(a.film->buffer()),
                                                         vk::BufferRange(*a.frame)};
  for (const auto& d : a.bvh->descriptors()) slots.push_back(d);
  for (const vk::BufferRange& r : a.scene->bindings()) slots.push_back(r);
  for (VkBufferView v : a.scene->texelViews()) slots.push_back(v);
  const uint32_t pixels = a.film->pixelCount();
  for (uint32_t done = 0; done < a.sampleCount;) {
    const uint32_t samples = std::min(kMaxSamplesPerDispatch, a.sampleCount - done);
    for (uint32_t first = 0; first < pixels; first += kMaxPixelsPerDispatch) {
      pt::Push push{first, std::min(kMaxPixelsPerDispatch, pixels - first), a.sampleIndex + done,
                    samples};
      pipeline_.bindDescriptorSpan(cmd, slots, push);
      pipeline_.dispatch(cmd, vk::groupCount(push.pixelCount, pt::kPtWorkgroupSize));
      vk::computeBarrier(cmd);
    }
    done += samples;
  }
}

}  // namespace osr::render
