// Runs bvh_trace_rays (or its alpha variant when a mask is given) over host rays, reading the
// BVH the way `access` says (Auto: the device's default), with `raysPerLane` rays per
// invocation (0: the pass's default).
#pragma once
#include <vector>

#include "bvh/trace_rays.h"
#include "shaders/shared/bvh_trace.h"
#include "vk/buffer.h"

namespace osr::test {

inline std::vector<gpu::bvh_trace::TraceHit> traceOnDevice(
    const vk::Context& ctx, const bvh::Bvh& tree, const std::vector<gpu::bvh_trace::TraceRay>& rays,
    uint32_t mode, const std::vector<uint32_t>* mask = nullptr,
    bvh::Access access = bvh::Access::Auto, uint32_t raysPerLane = 0) {
  using gpu::bvh_trace::TraceHit;
  using gpu::bvh_trace::TraceRay;
  vk::Buffer rayBuf(ctx, rays.size() * sizeof(TraceRay), vk::MemoryUse::DeviceLocal, "test rays");
  rayBuf.uploadVector(rays);
  vk::Buffer hitBuf(ctx, rays.size() * sizeof(TraceHit), vk::MemoryUse::DeviceLocal, "test hits");
  vk::Buffer maskBuf;
  if (mask) {
    maskBuf = vk::Buffer(ctx, mask->size() * 4, vk::MemoryUse::DeviceLocal, "test alpha mask");
    maskBuf.uploadVector(*mask);
  }
  bvh::TraceRaysPass pass(ctx, mask != nullptr, access);
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    bvh::TraceRaysPass::Args args;
    args.bvh = &tree;
    args.rays = rayBuf;
    args.hits = hitBuf;
    if (mask) args.alphaMask = maskBuf;
    args.rayCount = uint32_t(rays.size());
    args.mode = mode;
    if (raysPerLane) args.raysPerLane = raysPerLane;
    pass.record(cmd, args);
  });
  return hitBuf.downloadVector<TraceHit>(rays.size());
}

}  // namespace osr::test
