#include "bvh/trace_rays.h"

#include <algorithm>

#include "common/error.h"

namespace osr::bvh {

namespace tr = gpu::bvh_trace;

TraceRaysPass::TraceRaysPass(const vk::Context& ctx, bool alphaTest)
    : alphaTest_(alphaTest),
      pipeline_(ctx, alphaTest ? shaders::Id::bvh_trace_rays_alpha : shaders::Id::bvh_trace_rays,
                alphaTest ? tr::kBindingAlphaMask + 1 : tr::kBindingBvh + gpu::bvh::kBvhBindingCount,
                sizeof(tr::Push)) {}

void TraceRaysPass::record(VkCommandBuffer cmd, const Args& args) const {
  if (args.rayCount == 0) return;
  uint32_t groups = vk::groupCount(args.rayCount, tr::kWorkgroupSize);
  uint32_t x = std::min(groups, 65535u);
  uint32_t y = (groups + x - 1) / x;
  tr::Push push{args.rayCount, args.mode, x * tr::kWorkgroupSize, 0};
  auto bvh = args.bvh->bindings();
  if (alphaTest_)
    pipeline_.bind(cmd, {args.rays, args.hits, bvh[0], bvh[1], args.alphaMask}, push);
  else
    pipeline_.bind(cmd, {args.rays, args.hits, bvh[0], bvh[1]}, push);
  pipeline_.dispatch(cmd, x, y);
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
