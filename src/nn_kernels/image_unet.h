// The image denoiser's network (tools/image_unet.py, architectures "osr_image_kpn_v1" and
// "osr_image_unet_v1") on the device, one tile at a time: from a 9-channel input tensor
// (log1p(e colour), albedo, normal) to the output (100 kernel logits or 3 colour channels),
// both fp32 NCHW in this object's arena. A tile is th x tw pixels,
// multiples of kImageMultiple; each tensor is stored padded to the convolution tile (8) at
// its resolution and zero outside its valid region, which is the zero padding every layer
// of the network assumes, so a tile's result equals PyTorch's on that tile.
// Images larger than one tile run in overlapping tiles (src/denoise/network_denoiser.cpp):
// a tile's outputs farther than kImageTileMargin from its cut edges equal the whole image's.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "nn_kernels/conv.h"
#include "nn_kernels/net_plan.h"
#include "nn_kernels/resample.h"
#include "nn_kernels/weights.h"
#include "vk/buffer.h"
#include "vk/buffer_view.h"
#include "vk/timer.h"

namespace osr::nn {

// The network's receptive field reaches 38 pixels from an output (measured: the gradient of
// one output pixel w.r.t. the input, every phase of the 8-pixel pooling grid); rounded up to
// the pooling grid so that tile origins keep the whole image's pooling phase. The predicted
// kernels reach 30 pixels further (image_unet.KERNEL_RADIUS), each tap through its own
// pixel's network output: 68, rounded up.
inline constexpr uint32_t kImageReceptiveRadius = 38;
inline constexpr uint32_t kImageTileMargin = 40;
inline constexpr uint32_t kImageKernelRadius = 30;
inline constexpr uint32_t kImageKpnTileMargin = 72;

class ImageUNet {
 public:
  // Arena for tiles up to maxTile x maxTile (a multiple of 8): every tensor must fit one
  // storage binding and the arena `budget` bytes; see maxTileFor.
  ImageUNet(const vk::Context& ctx, const ImageUNetWeights& weights, uint32_t maxTile);

  // The largest tile side (multiple of 8) whose tensors fit the device's binding range and
  // `budget` bytes in all, for base width k and `outs` output channels.
  static uint32_t maxTileFor(const vk::Context& ctx, uint32_t k, uint32_t outs, uint64_t budget);

  // Records the network on a th x tw tile (multiples of 8, at most maxTile) whose input the
  // caller has written to input(); y lands in output(). Ends with a barrier.
  void record(VkCommandBuffer cmd, uint32_t th, uint32_t tw, vk::GpuTimer* timer = nullptr) const;

  // 9 x th x tw and outs x th x tw fp32, dense (a multiple of 8 needs no padding).
  vk::BufferRange input(uint32_t th, uint32_t tw) const;
  vk::BufferRange output(uint32_t th, uint32_t tw) const;

  uint32_t k() const { return k_; }
  uint32_t maxTile() const { return maxTile_; }
  double flopsPerPixel() const { return flopsPerPixel_; }

 private:
  struct Tensor {
    uint32_t channels, scale;  // channels; resolution 1 / 2^scale
    VkDeviceSize offset, bytes;
  };
  TensorView view(int tensor, uint32_t c0) const;

  const vk::Context& ctx_;
  uint32_t k_, outs_, maxTile_;
  double flopsPerPixel_ = 0;
  std::vector<ConvWeights> convs_;
  std::vector<ConvPass> convPasses_;
  std::vector<LayerSlot> layers_;
  std::unique_ptr<ResamplePass> pool_, upsample_;
  std::vector<Tensor> tensors_;
  vk::Buffer weightBuffer_, paramBuffer_, arena_;
  std::vector<vk::BufferView> weightViews_;  // per conv layer
  std::vector<vk::BufferView> tensorViews_;  // per tensor, as input texels (CPU devices)
};

}  // namespace osr::nn
