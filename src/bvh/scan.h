// The exclusive scan under the radix sort's digit counts.
#pragma once
#include <vulkan/vulkan.h>

#include "bvh/build_pass.h"

namespace osr::bvh {

// bvh_scan_reduce + bvh_scan_top + bvh_scan_apply: in-place exclusive scan of uints.
class ExclusiveScan {
 public:
  explicit ExclusiveScan(const vk::Context& ctx);
  static uint64_t partialsBytes(uint32_t count);
  struct Args {
    vk::BufferRange data;      // uint[count], scanned in place
    vk::BufferRange partials;  // scratch: partialsBytes(count)
    uint32_t count = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  vk::ComputePipeline reduce_, top_, apply_;
};

}  // namespace osr::bvh
