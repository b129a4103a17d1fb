// Stage 3 of the GPU BVH build: the triangles in Morton order.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/build_pass.h"
#include "bvh/scan.h"

namespace osr::bvh {

// Stable LSD radix sort of 30-bit keys with uint values: 4 rounds of histogram, scan, scatter.
// The result ends in keys/values (an even number of rounds through the ping-pong buffers).
class RadixSort {
 public:
  explicit RadixSort(const vk::Context& ctx);
  static uint64_t histogramBytes(uint32_t count);
  // Usage keys, values and their scratch twins need on top of storage use (their R32UI views).
  static constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  struct Args {
    vk::BufferRange keys, values;        // in/out
    vk::BufferRange keysTmp, valuesTmp;  // scratch, same sizes
    vk::BufferRange histogram;           // scratch: histogramBytes(count)
    vk::BufferRange partials;            // scratch: ExclusiveScan::partialsBytes(histogram words)
    uint32_t count = 0;
    // R32UI views (vk::BufferView::uintWords) of keys, values, keysTmp, valuesTmp.
    VkBufferView keyTexels = VK_NULL_HANDLE, valueTexels = VK_NULL_HANDLE;
    VkBufferView keyTmpTexels = VK_NULL_HANDLE, valueTmpTexels = VK_NULL_HANDLE;
  };
  // `timer` (may be null) gets scopes "bvh_radix_histogram", "bvh_scan", "bvh_radix_scatter".
  void record(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer = nullptr) const;

 private:
  vk::ComputePipeline histogram_, scatter_;
  ExclusiveScan scan_;
};

}  // namespace osr::bvh
