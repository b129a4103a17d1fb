#include "nn_kernels/conv.h"

#include <algorithm>
#include <cstring>

#include "common/error.h"
#include "shaders/shared/nn.h"
#include "vk/binder.h"

namespace osr::nn {

namespace g = gpu::nn;

namespace {
std::vector<VkDescriptorType> slotTypes() {
  std::vector<VkDescriptorType> types(g::kConvBindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  types[g::kBindingWeightTexels] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  types[g::kBindingInTexels] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return types;
}
}  // namespace

ConvPass::ConvPass(const vk::Context& ctx, const ConvConfig& config) : config_(config) {
  // One lane per output channel; a workgroup covers up to 64 channels of one pixel tile, at
  // least one subgroup (8 on lavapipe) so that no lane of a SIMD batch is always idle.
  const uint32_t sub = std::max(ctx.caps().subgroupSize, 8u);
  const uint32_t rounded = (config.cout + sub - 1) / sub * sub;
  workgroup_ = std::min(rounded, 64u);
  // Tile of output pixels per lane: the accumulators amortise the per-lane weight loads and
  // the shared footprint loads. On lavapipe 8x8 (64 accumulators, spilled) costs less per map
  // than smaller tiles (docs/device_notes.md, "The U-Net's kernels"); GPUs keep 32 registers.
  const uint32_t defaultH = ctx.caps().isCpu() ? 8u : 4u;
  tileW_ = config.tileW ? config.tileW : std::min(config.width, 8u);
  tileH_ = config.tileH ? config.tileH : std::min(config.width, defaultH);
  if (config.width % tileW_ || config.width % tileH_ || tileW_ % 4)
    throw InputError("conv tile " + std::to_string(tileH_) + "x" + std::to_string(tileW_) +
                     " does not divide width " + std::to_string(config.width));
  // CPU Vulkan turns each buffer access into a loop over lanes; sharing loads across the
  // subgroup pays there. The workgroup is a multiple of the subgroup, so subgroups are full.
  const uint32_t share = config.shareLoads >= 0 ? uint32_t(config.shareLoads)
                         : ctx.caps().isCpu()   ? ctx.caps().subgroupSize
                                                : 0u;
  inputTexels_ = config.inputTexels && share > 0;
  if (share && (workgroup_ % share || share != ctx.caps().subgroupSize))
    throw DeviceError("nn_conv: load sharing needs whole subgroups");
  pipeline_ = vk::ComputePipeline(
      ctx, shaders::Id::nn_conv,
      slotTypes(),
      sizeof(g::ConvPush),
      {vk::specUint(g::kSpecWorkgroup, workgroup_), vk::specUint(g::kSpecInHalf, config.inHalf),
       vk::specUint(g::kSpecOutHalf, config.outHalf),
       vk::specUint(g::kSpecWeightHalf, config.weightHalf),
       vk::specUint(g::kSpecKernel, config.kernel), vk::specUint(g::kSpecTileH, tileH_),
       vk::specUint(g::kSpecTileW, tileW_),
       vk::specUint(g::kSpecActivation, uint32_t(config.activation)),
       vk::specUint(g::kSpecBatchNorm, config.batchNorm), vk::specFloat(g::kSpecSlope, config.slope),
       vk::specUint(g::kSpecShare, share),
       vk::specUint(g::kSpecWeightTexel, config.weightTexels),
       vk::specUint(g::kSpecInTexel, inputTexels_)});
}

std::vector<uint32_t> ConvPass::packWeights(const ConvWeights& conv) const {
  // [cin / 4][tap][coutPadded][4 input channels]: a lane reads its 4 weights of one tap with
  // one 16-byte (fp32) or 8-byte (fp16) load; zero for padding channels.
  const uint32_t taps = conv.kernel * conv.kernel;
  const uint32_t padded = coutPadded(conv.cout);
  const uint32_t groups = (conv.cin + 3) / 4;
  std::vector<float> w(size_t(groups) * taps * padded * 4, 0.0f);
  for (uint32_t co = 0; co < conv.cout; ++co)
    for (uint32_t ci = 0; ci < conv.cin; ++ci)
      for (uint32_t t = 0; t < taps; ++t)
        w[((size_t(ci / 4) * taps + t) * padded + co) * 4 + ci % 4] =
            conv.weight[(size_t(co) * conv.cin + ci) * taps + t];
  std::vector<uint32_t> words;
  if (config_.weightHalf) {
    words.resize(w.size() / 2, 0);
    for (size_t i = 0; i < w.size(); ++i) words[i / 2] |= uint32_t(floatToHalf(w[i])) << (16 * (i % 2));
  } else {
    words.resize(w.size());
    std::memcpy(words.data(), w.data(), w.size() * 4);
  }
  return words;
}

std::vector<float> ConvPass::packParams(const ConvWeights& conv) const {
  const uint32_t padded = coutPadded(conv.cout);
  std::vector<float> p(3 * size_t(padded), 0.0f);
  std::copy(conv.bias.begin(), conv.bias.end(), p.begin());
  std::copy(conv.scale.begin(), conv.scale.end(), p.begin() + padded);
  std::copy(conv.shift.begin(), conv.shift.end(), p.begin() + 2 * padded);
  return p;
}

void ConvPass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.src.half != config_.inHalf || a.dst.half != config_.outHalf)
    throw DeviceError("nn_conv: arguments do not match the pass's specialisation");
  const uint32_t w = a.width ? a.width : config_.width, h = a.height ? a.height : config_.width;
  if (w % tileW_ || h % tileH_)
    throw DeviceError("nn_conv: " + std::to_string(w) + "x" + std::to_string(h) +
                      " is not a multiple of the tile");
  g::ConvPush push{};
  push.src = {a.src.cTotal, a.src.c0, 0, 0};
  push.dst = {a.dst.cTotal, a.dst.c0, 0, 0};
  push.maps = a.maps;
  push.cin = a.cin;
  push.cout = a.cout;
  push.coutPadded = coutPadded(a.cout);
  push.height = h;
  push.width = w;
  push.validHeight = a.validHeight ? a.validHeight : h;
  push.validWidth = a.validWidth ? a.validWidth : w;
  const uint64_t tiles = uint64_t(a.maps) * (h / tileH_) * (w / tileW_);
  push.tileCount = uint32_t(tiles);
  uint32_t gy, gz;
  splitGroups(tiles, gy, gz);
  push.tileGroupsY = gy;
  if (inputTexels_ && !a.srcTexels) throw DeviceError("nn_conv: input texel view missing");
  // Without input texels the slot still needs a valid view; the shader never reads it.
  vk::Binder(pipeline_)
      .set(g::kBindingIn, a.src.range)
      .set(g::kBindingOut, a.dst.range)
      .set(g::kBindingWeights, a.weights)
      .set(g::kBindingParams, a.params)
      .setTexel(g::kBindingWeightTexels, a.weightTexels)
      .setTexel(g::kBindingInTexels, inputTexels_ ? a.srcTexels : a.weightTexels)
      .bind(cmd, push);
  pipeline_.dispatch(cmd, push.coutPadded / workgroup_, gy, gz);
  vk::computeBarrier(cmd);
}

}  // namespace osr::nn
