#include "pt/trace_pass.h"

#include <algorithm>
#include <vector>

#include "vk/binder.h"

namespace osr::pt {

namespace g = gpu::pt;

static_assert(g::kPtSceneBinding == g::kPtBvhBinding + gpu::bvh::kBvhBindingCount);
static_assert(g::kPtSceneTexelBinding == g::kPtSceneBinding + gpu::scene::kSceneBindingCount);
static_assert(g::kPtBindingCount == g::kPtSceneTexelBinding + gpu::scene::kSceneTexelBindingCount);

namespace {
std::vector<VkDescriptorType> descriptorTypes() {
  std::vector<VkDescriptorType> types(g::kPtBindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  auto bvhTypes = bvh::Bvh::descriptorTypes();
  std::copy(bvhTypes.begin(), bvhTypes.end(), types.begin() + g::kPtBvhBinding);
  std::fill(types.begin() + g::kPtSceneTexelBinding, types.end(),
            VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER);
  return types;
}

uint32_t shaderIntegrator(Mode mode) {
  return mode == Mode::Preview ? g::kIntegratorPreview : g::kIntegratorPath;
}
}  // namespace

TracePass::TracePass(const vk::Context& ctx, Mode mode, uint32_t sceneFeatures,
                     bool sceneTexelFetch)
    : pipeline_(ctx, shaders::Id::pt_trace, descriptorTypes(), sizeof(g::Push),
                {vk::specUint(g::kPtSpecIntegrator, shaderIntegrator(mode)),
                 vk::specUint(g::kPtSpecSceneFeatures, sceneFeatures), bvh::traversalSpec(ctx),
                 vk::specUint(gpu::scene::kSceneSpecTexelFetch, sceneTexelFetch ? 1u : 0u)}),
      filmWindow_(render::windowPixels(ctx, sizeof(gpu::film::FilmPixel))) {}

void TracePass::record(VkCommandBuffer cmd, const Args& a) const {
  const vk::ComputePipeline& pipeline = pipeline_.forBvh(*a.bvh);
  vk::Binder binder(pipeline);
  binder.set(g::kPtBindingFrame, *a.frame);
  a.bvh->bind(binder, g::kPtBvhBinding);
  a.scene->bind(binder, g::kPtSceneBinding);
  a.scene->bindTexels(binder, g::kPtSceneTexelBinding);
  const uint32_t begin = std::min(a.pixelFirst, a.film->pixelCount());
  const uint32_t end = begin + std::min(a.pixelCount, a.film->pixelCount() - begin);
  // Each dispatch binds its own window of the film (render/film.h).
  const uint32_t perDispatch = std::min(kMaxPixelsPerDispatch, filmWindow_);
  for (uint32_t done = 0; done < a.sampleCount;) {
    const uint32_t samples = std::min(kMaxSamplesPerDispatch, a.sampleCount - done);
    for (uint32_t first = begin; first < end; first += perDispatch) {
      g::Push push{first, std::min(perDispatch, end - first), a.sampleIndex + done, samples};
      binder.set(g::kPtBindingFilm, a.film->window(push.pixelOffset, push.pixelCount));
      binder.bind(cmd, push);
      pipeline.dispatch(cmd, vk::groupCount(push.pixelCount, g::kPtWorkgroupSize));
      vk::computeBarrier(cmd);
    }
    done += samples;
  }
}

}  // namespace osr::pt
