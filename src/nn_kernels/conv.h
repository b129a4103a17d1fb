// The convolution pass of the U-Net (shaders/nn_conv.comp): 3x3 or 1x1, zero padding, bias,
// activation, optional per-channel scale and shift after it, reading and writing channel
// slices. Specialised per layer shape class; channel counts are push constants.
#pragma once
#include <cstdint>
#include <vector>

#include "nn_kernels/tensor_view.h"
#include "nn_kernels/weights.h"
#include "vk/pipeline.h"

namespace osr::nn {

struct ConvConfig {
  uint32_t kernel = 3;
  uint32_t cout = 0;    // picks the workgroup size; a pass serves any cout with that size
  uint32_t width = 32;  // square maps; picks the tile
  Activation activation = Activation::LeakyRelu;
  float slope = 0.2f;
  bool batchNorm = false;
  bool inHalf = false, outHalf = false, weightHalf = false;
  uint32_t tileH = 0, tileW = 0;  // 0: chosen for the device (conv.cpp); tileW % 4 == 0
  int shareLoads = -1;  // lanes sharing input loads: -1 per device (CPU: subgroup size), 0: off
  bool weightTexels = true;  // read weights through Args::weightTexels (else the buffer)
  bool inputTexels = false;  // with load sharing: read the input through Args::srcTexels
};

class ConvPass {
 public:
  ConvPass(const vk::Context& ctx, const ConvConfig& config);

  struct Args {
    TensorView src, dst;      // src.half / dst.half must match the config
    vk::BufferRange weights;  // packWeights() words
    VkBufferView weightTexels = VK_NULL_HANDLE;  // the same range, weightTexelFormat()
    VkBufferView srcTexels = VK_NULL_HANDLE;  // src.range as texelFormat(src.half), if inputTexels
    vk::BufferRange params;   // packParams() floats
    uint32_t maps = 0;
    uint32_t cin = 0, cout = 0;
    // Size as stored, multiples of the tile (0: the config's square width), and the valid
    // top-left region outside which outputs are stored as zero (0: all of it).
    uint32_t height = 0, width = 0;
    uint32_t validHeight = 0, validWidth = 0;
  };
  // Records the dispatch and a barrier after it. Ranges must fit maxStorageBufferRange.
  void record(VkCommandBuffer cmd, const Args& args) const;

  uint32_t workgroup() const { return workgroup_; }
  // Weight and parameter row length for `cout` output channels: a workgroup multiple.
  uint32_t coutPadded(uint32_t cout) const { return (cout + workgroup_ - 1) / workgroup_ * workgroup_; }
  uint32_t tileH() const { return tileH_; }
  uint32_t tileW() const { return tileW_; }
  // Device layout of the weights (see packWeights in conv.cpp), fp32 or packed fp16.
  std::vector<uint32_t> packWeights(const ConvWeights& conv) const;
  // RGBA texels of 4 consecutive pixels of an activation tensor.
  static VkFormat texelFormat(bool half) {
    return half ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R32G32B32A32_SFLOAT;
  }
  VkFormat weightTexelFormat() const {
    return config_.weightHalf ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R32G32B32A32_SFLOAT;
  }
  // bias, scale, shift, each coutPadded fp32.
  std::vector<float> packParams(const ConvWeights& conv) const;

 private:
  ConvConfig config_;
  bool inputTexels_ = false;
  uint32_t workgroup_ = 0, tileH_ = 0, tileW_ = 0;
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::nn
