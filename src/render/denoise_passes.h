// The image denoisers' compute passes (shaders/denoise_*.comp, shaders/shared/denoise.h), one
// class per pass; render/denoiser.h puts them together. Every pass binds the same seven slots
// (DenoiseBindings); a pass's unused slots get any valid range.
#pragma once
#include <cstdint>

#include "shaders/shared/denoise.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace osr::render {

struct DenoiseBindings {
  vk::BufferRange colour, albedo, normal;  // image layers (shared/denoise.h)
  vk::BufferRange exposure;                // ExposureSums[kExposurePartials + 1]
  vk::BufferRange tensor;                  // the network tile's input or output tensor
  vk::BufferRange out;                     // vec4 per pixel
  vk::BufferRange denoised;                // convergence: the denoised colour, vec4 per pixel
};

// The exposure scale e of the padded image (denoise_exposure.comp, both stages).
class ExposurePass {
 public:
  explicit ExposurePass(const vk::Context& ctx);
  void record(VkCommandBuffer cmd, const DenoiseBindings& b, const gpu::denoise::DenoisePush& push) const;

 private:
  vk::ComputePipeline partials_, total_;
};

// A tile's network input from the image layers (denoise_net_input.comp).
class NetInputPass {
 public:
  explicit NetInputPass(const vk::Context& ctx);
  void record(VkCommandBuffer cmd, const DenoiseBindings& b, const gpu::denoise::DenoisePush& push) const;

 private:
  vk::ComputePipeline pipeline_;
};

// A tile core's colour from the network output (denoise_net_output.comp).
class NetOutputPass {
 public:
  explicit NetOutputPass(const vk::Context& ctx);
  void record(VkCommandBuffer cmd, const DenoiseBindings& b, const gpu::denoise::DenoisePush& push) const;

 private:
  vk::ComputePipeline pipeline_;
};

// One level of the kernel-predicting network's kernels on a tile (denoise_kernel_apply.comp):
// the first reads the image colour (b.colour) and demodulates it, the others the previous
// level's tile buffer (b.colour); the last writes the core's re-modulated colour to the image
// (b.out), the others the whole tile to a tile buffer (b.out). b.tensor: the logits. factors:
// what each tap's weight is multiplied by besides the network's (gpu::denoise::KernelFactors:
// nothing, the fixed normal and depth factors of osr_image_kpn_v2, or those and the a-trous
// filter's of osr_image_kpn_v3, and of osr_image_kpn_v4 with the filter's normal factor on edges).
class KernelApplyPass {
 public:
  KernelApplyPass(const vk::Context& ctx, bool first, bool last, uint32_t factors);
  void record(VkCommandBuffer cmd, const DenoiseBindings& b, const gpu::denoise::DenoisePush& push) const;

 private:
  bool last_;
  vk::ComputePipeline pipeline_;
};

// One a-trous iteration (denoise_atrous.comp) from b.colour into b.out; the first demodulates
// the colour by the albedo, the last re-modulates.
class AtrousPass {
 public:
  AtrousPass(const vk::Context& ctx, bool first, bool last);
  void record(VkCommandBuffer cmd, const DenoiseBindings& b, const gpu::denoise::DenoisePush& push) const;

 private:
  vk::ComputePipeline pipeline_;
};

// The denoised colour (b.denoised) plus the film's (b.colour) mean gap from it over the pixel's
// neighbours of the same geometry, where that gap is more than the film's noise explains
// (denoise_bias.comp), into b.out: the first of the two convergence passes.
class BiasPass {
 public:
  explicit BiasPass(const vk::Context& ctx);
  void record(VkCommandBuffer cmd, const DenoiseBindings& b, const gpu::denoise::DenoisePush& push) const;

 private:
  vk::ComputePipeline pipeline_;
};

// The denoised colour (b.denoised) moved back towards the film's (b.colour) where they differ by
// more than the film's noise explains (denoise_converge.comp), into b.out: the second
// convergence pass, after BiasPass.
class ConvergePass {
 public:
  explicit ConvergePass(const vk::Context& ctx);
  void record(VkCommandBuffer cmd, const DenoiseBindings& b, const gpu::denoise::DenoisePush& push) const;

 private:
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::render
