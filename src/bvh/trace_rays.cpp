#include "bvh/trace_rays.h"

#include <algorithm>
#include <string>
#include <vector>

#include "common/error.h"

namespace osr::bvh {

namespace tr = gpu::bvh_trace;

static_assert(tr::kBindingAlphaMask == tr::kBindingBvh + gpu::bvh::kBvhBindingCount);

namespace {
std::vector<VkDescriptorType> descriptorTypes(bool alphaTest) {
  std::vector<VkDescriptorType> types(
      alphaTest ? tr::kBindingAlphaMask + 1 : tr::kBindingBvh + gpu::bvh::kBvhBindingCount,
      VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  const auto bvhTypes = Bvh::descriptorTypes();
  std::copy(bvhTypes.begin(), bvhTypes.end(), types.begin() + tr::kBindingBvh);
  return types;
}
}  // namespace

TraceRaysPass::TraceRaysPass(const vk::Context& ctx, bool alphaTest, Access access)
    : alphaTest_(alphaTest),
      storageAccess_(traversalSpec(ctx, access).bits == 0),
      pooled_(ctx, alphaTest ? shaders::Id::bvh_trace_rays_alpha : shaders::Id::bvh_trace_rays,
              descriptorTypes(alphaTest), sizeof(tr::Push),
              {traversalSpec(ctx, access), vk::specUint(tr::kSpecRayPool, 1)}),
      single_(ctx, alphaTest ? shaders::Id::bvh_trace_rays_alpha : shaders::Id::bvh_trace_rays,
              descriptorTypes(alphaTest), sizeof(tr::Push),
              {traversalSpec(ctx, access), vk::specUint(tr::kSpecRayPool, 0)}) {}

void TraceRaysPass::record(VkCommandBuffer cmd, const Args& args) const {
  if (args.rayCount == 0) return;
  // Bvh::bind cuts a storage slot at maxStorageBufferRange; only texel fetch reads past it.
  if (storageAccess_ && std::max(args.bvh->traversedNodes().size(), args.bvh->leafData.size()) > args.bvh->storageRange)
    throw DeviceError("bvh: a BVH of " + std::to_string(args.bvh->triangleCount) +
                      " triangles passes maxStorageBufferRange (" + std::to_string(args.bvh->storageRange >> 20) +
                      " MiB), which storage-buffer traversal cannot read; use texel fetch");
  // Capped so that neither the group count nor a subgroup's pool end can wrap.
  const uint32_t raysPerLane = std::clamp(args.raysPerLane, 1u, 1024u);
  uint32_t groups = vk::groupCount((args.rayCount + raysPerLane - 1) / raysPerLane, tr::kWorkgroupSize);
  uint32_t x = std::min(groups, 65535u);
  uint32_t y = (groups + x - 1) / x;
  tr::Push push{args.rayCount, args.mode, raysPerLane, 0};
  const vk::ComputePipeline& pipeline = (raysPerLane > 1 ? pooled_ : single_).forBvh(*args.bvh);
  vk::Binder binder(pipeline);
  binder.set(tr::kBindingRays, args.rays).set(tr::kBindingHits, args.hits);
  args.bvh->bind(binder, tr::kBindingBvh);
  if (alphaTest_) binder.set(tr::kBindingAlphaMask, args.alphaMask);
  binder.bind(cmd, push);
  pipeline.dispatch(cmd, x, y);
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
