#include "nn_kernels/resample.h"

#include "common/error.h"
#include "shaders/shared/nn.h"
#include "vk/binder.h"

namespace osr::nn {

namespace g = gpu::nn;

ResamplePass::ResamplePass(const vk::Context& ctx, Resample kind, bool inHalf, bool outHalf)
    : kind_(kind), inHalf_(inHalf), outHalf_(outHalf) {
  pipeline_ = vk::ComputePipeline(
      ctx, kind == Resample::MaxPool2x2 ? shaders::Id::nn_maxpool : shaders::Id::nn_upsample,
      g::kResampleBindingCount,
      sizeof(g::PoolPush),
      {vk::specUint(g::kSpecWorkgroup, g::kElementwiseWorkgroup),
       vk::specUint(g::kSpecInHalf, inHalf), vk::specUint(g::kSpecOutHalf, outHalf)});
}

void ResamplePass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.src.half != inHalf_ || a.dst.half != outHalf_)
    throw DeviceError("nn resample: arguments do not match the pass's specialisation");
  const bool pool = kind_ == Resample::MaxPool2x2;
  const uint32_t inH = a.inHeight ? a.inHeight : a.inWidth;
  const uint32_t outW = a.outWidth ? a.outWidth : pool ? a.inWidth / 2 : a.inWidth * 2;
  const uint32_t outH = a.outHeight ? a.outHeight : pool ? inH / 2 : inH * 2;
  g::PoolPush push{};
  push.src = {a.src.cTotal, a.src.c0, 0, 0};
  push.dst = {a.dst.cTotal, a.dst.c0, 0, 0};
  push.maps = a.maps;
  push.channels = a.channels;
  push.inHeight = inH;
  push.inWidth = a.inWidth;
  push.outHeight = outH;
  push.outWidth = outW;
  push.validInHeight = a.validInHeight ? a.validInHeight : inH;
  push.validInWidth = a.validInWidth ? a.validInWidth : a.inWidth;
  const uint64_t pairs = uint64_t(a.maps) * a.channels * outW * outH / 2;
  push.pairCount = uint32_t(pairs);
  uint32_t gx, gy;
  splitGroups((pairs + g::kElementwiseWorkgroup - 1) / g::kElementwiseWorkgroup, gx, gy);
  push.groupsX = gx;
  vk::Binder(pipeline_).set(g::kBindingIn, a.src.range).set(g::kBindingOut, a.dst.range).bind(cmd, push);
  pipeline_.dispatch(cmd, gx, gy);
  vk::computeBarrier(cmd);
}

}  // namespace osr::nn
