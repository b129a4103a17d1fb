#include "bvh/trace_rays.h"

#include <algorithm>
#include <vector>

#include "common/error.h"

namespace osr::bvh {

namespace tr = gpu::bvh_trace;

static_assert(tr::kBindingAlphaMask == tr::kBindingBvh + gpu::bvh::kBvhBindingCount);

namespace {
std::vector<VkDescriptorType> descriptorTypes(bool alphaTest) {
  std::vector<VkDescriptorType> types(tr::kBindingBvh, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  for (VkDescriptorType t : Bvh::descriptorTypes()) types.push_back(t);
  if (alphaTest) types.push_back(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  return types;
}
}  // namespace

TraceRaysPass::TraceRaysPass(const vk::Context& ctx, bool alphaTest, Access access)
    : alphaTest_(alphaTest),
      pipeline_(ctx, alphaTest ? shaders::Id::bvh_trace_rays_alpha : shaders::Id::bvh_trace_rays,
                descriptorTypes(alphaTest), sizeof(tr::Push), {traversalSpec(ctx, access)}) {}

void TraceRaysPass::record(VkCommandBuffer cmd, const Args& args) const {
  if (args.rayCount == 0) return;
  uint32_t groups = vk::groupCount(args.rayCount, tr::kWorkgroupSize);
  uint32_t x = std::min(groups, 65535u);
  uint32_t y = (groups + x - 1) / x;
  tr::Push push{args.rayCount, args.mode, x * tr::kWorkgroupSize, 0};
  std::vector<vk::ComputePipeline::Descriptor> slots = {args.rays, args.hits};
  for (const auto& d : args.bvh->descriptors()) slots.push_back(d);
  if (alphaTest_) slots.push_back(args.alphaMask);
  pipeline_.bindDescriptorSpan(cmd, slots, push);
  pipeline_.dispatch(cmd, x, y);
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
