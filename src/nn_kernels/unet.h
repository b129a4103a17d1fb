// The U-Net on the device: records the whole network over N maps into a command buffer, from
// a device buffer of N x 7 x 32 x 32 fp32 maps to one of N x 3 x 32 x 32 fp32 predictions, so
// the OSR pass runs it between tracing and compositing with no host round trip. Maps are
// processed in chunks that keep every binding under maxStorageBufferRange and the scratch
// arena under a memory budget.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "nn_kernels/conv.h"
#include "nn_kernels/resample.h"
#include "nn_kernels/weights.h"
#include "vk/buffer.h"
#include "vk/buffer_view.h"
#include "vk/timer.h"

namespace osr::nn {

struct UNetOptions {
  bool half = false;                    // fp16 activations and weights (fp32 arithmetic)
  uint32_t maxChunk = 1024;             // maps per chunk at most
  uint64_t scratchBudget = 768ull << 20;  // bytes of intermediate activations at most
  uint32_t tileH = 0, tileW = 0;        // conv tile override (0: per device)
  int shareLoads = -1;                  // conv input-load sharing override (-1: per device)
};

class UNet {
 public:
  UNet(const vk::Context& ctx, const UNetWeights& weights, const UNetOptions& options = {});

  // Records the network for `maps` maps. `in` holds maps * 7 * 32 * 32 fp32 from inOffset,
  // `out` receives maps * 3 * 32 * 32 fp32 at outOffset; offsets are multiples of 256 bytes.
  // Ends with a barrier, so later compute passes can read `out`.
  void record(VkCommandBuffer cmd, const vk::Buffer& in, VkDeviceSize inOffset,
              const vk::Buffer& out, VkDeviceSize outOffset, uint32_t maps,
              vk::GpuTimer* timer = nullptr) const;

  uint32_t k() const { return k_; }
  uint32_t chunkMaps() const { return chunk_; }
  double flopsPerMap() const { return flopsPerMap_; }

 private:
  struct Scratch {
    uint32_t channels, width;
    VkDeviceSize offset, bytes;
  };
  struct ConvLayer {
    size_t pass;  // index into convPasses_
    uint32_t cin, cout;
    VkDeviceSize weightOffset, weightBytes, paramOffset, paramBytes;
  };
  TensorView view(int scratch, uint32_t c0) const;

  const vk::Context& ctx_;
  uint32_t k_;
  bool half_;
  uint32_t chunk_ = 0;
  double flopsPerMap_ = 0;
  std::vector<ConvPass> convPasses_;
  std::vector<ConvLayer> layers_;
  std::unique_ptr<ResamplePass> pool_, upsample_;
  std::vector<Scratch> scratch_;
  vk::Buffer weightBuffer_, paramBuffer_, arena_;
  std::vector<vk::BufferView> weightViews_;  // per conv layer, in layers_ order
  std::vector<vk::BufferView> scratchViews_;  // per scratch tensor, as input texels
};

}  // namespace osr::nn
