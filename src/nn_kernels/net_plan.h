// What the two U-Nets (unet.cpp: maps; image_unet.cpp: images) share in laying out their
// forward pass: the step table form, tensor alignment, and the packing of each layer's
// weights and epilogue parameters for its convolution pass into one buffer each.
#pragma once
#include <cstdint>
#include <vector>

#include "nn_kernels/conv.h"
#include "nn_kernels/weights.h"

namespace osr::nn {

enum class Op { Conv, Pool, Up };
// One pass of a forward table: the conv (layer index) or resample, source and destination
// tensor with the first channel of each as a multiple of K, and the resampled channels
// (times K). Concatenations are channel ranges written by two producers.
struct Step {
  Op op;
  int conv;
  int src;
  uint32_t srcC0TimesK;
  int dst;
  uint32_t dstC0TimesK;
  uint32_t channelsTimesK;
};

inline constexpr VkDeviceSize kTensorAlign = 256;  // >= min storage and texel offset alignments
inline VkDeviceSize alignTensor(VkDeviceSize v) { return (v + kTensorAlign - 1) / kTensorAlign * kTensorAlign; }

// The workgroup size class ConvPass picks for `cout` channels (passes are shared by class).
inline uint32_t convWorkgroupClass(const vk::Context& ctx, uint32_t cout) {
  const uint32_t sub = std::max(ctx.caps().subgroupSize, 8u);
  return std::min((cout + sub - 1) / sub * sub, 64u);
}

// Where one layer's packed weights and parameters lie in the shared buffers.
struct LayerSlot {
  size_t pass;
  VkDeviceSize weightOffset, weightBytes, paramOffset, paramBytes;
};

// Appends `conv` packed for `pass` (index passIndex) to words and params, each aligned.
inline LayerSlot packLayer(const ConvPass& pass, size_t passIndex, const ConvWeights& conv,
                           std::vector<uint32_t>& words, std::vector<float>& params) {
  const std::vector<uint32_t> w = pass.packWeights(conv);
  const std::vector<float> p = pass.packParams(conv);
  LayerSlot slot{passIndex, words.size() * 4, w.size() * 4, params.size() * 4, p.size() * 4};
  words.insert(words.end(), w.begin(), w.end());
  words.resize(alignTensor(words.size() * 4) / 4, 0);
  params.insert(params.end(), p.begin(), p.end());
  params.resize(alignTensor(params.size() * 4) / 4, 0.0f);
  return slot;
}

}  // namespace osr::nn
