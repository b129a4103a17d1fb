// The U-Net's resolution changes: 2x2 max-pool (nn_maxpool.comp) and bilinear x2 upsampling
// with align_corners=False (nn_upsample.comp), each between channel-slice views.
#pragma once
#include <cstdint>

#include "nn_kernels/tensor_view.h"
#include "vk/pipeline.h"

namespace osr::nn {

enum class Resample { MaxPool2x2, Upsample2x };

class ResamplePass {
 public:
  ResamplePass(const vk::Context& ctx, Resample kind, bool inHalf, bool outHalf);

  struct Args {
    TensorView src, dst;
    uint32_t maps = 0, channels = 0;
    uint32_t inWidth = 0;  // square maps; even for the pool
    // Rectangular tensors stored padded: input height (0: inWidth), output size as stored
    // (0: half or twice the input), valid input region (0: all of the input).
    uint32_t inHeight = 0, outWidth = 0, outHeight = 0;
    uint32_t validInWidth = 0, validInHeight = 0;
  };
  // Records the dispatch and a barrier after it.
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  Resample kind_;
  bool inHalf_, outHalf_;
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::nn
