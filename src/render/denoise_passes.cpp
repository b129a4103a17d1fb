#include "render/denoise_passes.h"

#include "vk/binder.h"

namespace osr::render {

namespace g = gpu::denoise;

namespace {

vk::ComputePipeline makePipeline(const vk::Context& ctx, shaders::Id shader,
                                 const std::vector<vk::SpecConstant>& spec = {}) {
  return vk::ComputePipeline(ctx, shader, g::kDenoiseBindingCount, sizeof(g::DenoisePush), spec);
}

void bindAll(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, const DenoiseBindings& b,
             const g::DenoisePush& push) {
  // Slots a pass does not read get the colour layer: a valid range the shader never touches.
  auto or_colour = [&](const vk::BufferRange& r) { return r.buffer ? r : b.colour; };
  vk::Binder(pipeline)
      .set(g::kBindingColour, b.colour)
      .set(g::kBindingAlbedo, or_colour(b.albedo))
      .set(g::kBindingNormal, or_colour(b.normal))
      .set(g::kBindingExposure, or_colour(b.exposure))
      .set(g::kBindingTensor, or_colour(b.tensor))
      .set(g::kBindingOut, or_colour(b.out))
      .set(g::kBindingDenoised, or_colour(b.denoised))
      .bind(cmd, push);
}

uint32_t groups(uint32_t pixels) { return (pixels + g::kDenoiseTile - 1) / g::kDenoiseTile; }

// A pass with one invocation per pixel of the whole image.
void recordOverImage(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, const DenoiseBindings& b,
                     const g::DenoisePush& push) {
  bindAll(cmd, pipeline, b, push);
  pipeline.dispatch(cmd, groups(push.width), groups(push.height));
  vk::computeBarrier(cmd);
}

}  // namespace

ExposurePass::ExposurePass(const vk::Context& ctx)
    : partials_(makePipeline(ctx, shaders::Id::denoise_exposure, {vk::specUint(g::kSpecExposureStage, 0)})),
      total_(makePipeline(ctx, shaders::Id::denoise_exposure, {vk::specUint(g::kSpecExposureStage, 1)})) {}

void ExposurePass::record(VkCommandBuffer cmd, const DenoiseBindings& b, const g::DenoisePush& push) const {
  bindAll(cmd, partials_, b, push);
  partials_.dispatch(cmd, g::kExposurePartials);
  vk::computeBarrier(cmd);
  bindAll(cmd, total_, b, push);
  total_.dispatch(cmd, 1);
  vk::computeBarrier(cmd);
}

NetInputPass::NetInputPass(const vk::Context& ctx) : pipeline_(makePipeline(ctx, shaders::Id::denoise_net_input)) {}

void NetInputPass::record(VkCommandBuffer cmd, const DenoiseBindings& b, const g::DenoisePush& push) const {
  bindAll(cmd, pipeline_, b, push);
  pipeline_.dispatch(cmd, groups(push.tileWidth), groups(push.tileHeight));
  vk::computeBarrier(cmd);
}

NetOutputPass::NetOutputPass(const vk::Context& ctx) : pipeline_(makePipeline(ctx, shaders::Id::denoise_net_output)) {}

void NetOutputPass::record(VkCommandBuffer cmd, const DenoiseBindings& b, const g::DenoisePush& push) const {
  bindAll(cmd, pipeline_, b, push);
  pipeline_.dispatch(cmd, groups(push.coreX1 - push.coreX0), groups(push.coreY1 - push.coreY0));
  vk::computeBarrier(cmd);
}

KernelApplyPass::KernelApplyPass(const vk::Context& ctx, bool first, bool last, uint32_t factors)
    : last_(last),
      pipeline_(makePipeline(ctx, shaders::Id::denoise_kernel_apply,
                             {vk::specUint(g::kSpecKernelFirst, first), vk::specUint(g::kSpecKernelLast, last),
                              vk::specUint(g::kSpecKernelGuided, factors)})) {}

void KernelApplyPass::record(VkCommandBuffer cmd, const DenoiseBindings& b, const g::DenoisePush& push) const {
  bindAll(cmd, pipeline_, b, push);
  if (last_)
    pipeline_.dispatch(cmd, groups(push.coreX1 - push.coreX0), groups(push.coreY1 - push.coreY0));
  else
    pipeline_.dispatch(cmd, groups(push.tileWidth), groups(push.tileHeight));
  vk::computeBarrier(cmd);
}

AtrousPass::AtrousPass(const vk::Context& ctx, bool first, bool last)
    : pipeline_(makePipeline(ctx, shaders::Id::denoise_atrous,
                             {vk::specUint(g::kSpecAtrousFirst, first), vk::specUint(g::kSpecAtrousLast, last)})) {}

void AtrousPass::record(VkCommandBuffer cmd, const DenoiseBindings& b, const g::DenoisePush& push) const {
  recordOverImage(cmd, pipeline_, b, push);
}

BiasPass::BiasPass(const vk::Context& ctx) : pipeline_(makePipeline(ctx, shaders::Id::denoise_bias)) {}

void BiasPass::record(VkCommandBuffer cmd, const DenoiseBindings& b, const g::DenoisePush& push) const {
  recordOverImage(cmd, pipeline_, b, push);
}

ConvergePass::ConvergePass(const vk::Context& ctx) : pipeline_(makePipeline(ctx, shaders::Id::denoise_converge)) {}

void ConvergePass::record(VkCommandBuffer cmd, const DenoiseBindings& b, const g::DenoisePush& push) const {
  recordOverImage(cmd, pipeline_, b, push);
}

}  // namespace osr::render
