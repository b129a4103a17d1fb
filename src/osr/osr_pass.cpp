#include "osr/osr_pass.h"

#include <algorithm>

#include "bvh/bvh.h"
#include "nn_kernels/tensor_view.h"
#include "osr/osr_buffers.h"

namespace osr::oneshot {

namespace o = gpu::osr;

namespace {
std::vector<vk::SpecConstant> specs(const vk::Context& ctx, uint32_t sceneFeatures,
                                    bool sceneTexelFetch, std::vector<vk::SpecConstant> extra) {
  extra.push_back(vk::specUint(o::kOsrSpecSceneFeatures, sceneFeatures));
  extra.push_back(bvh::traversalSpec(ctx));
  extra.push_back(vk::specUint(gpu::scene::kSceneSpecTexelFetch, sceneTexelFetch ? 1u : 0u));
  return extra;
}
}  // namespace

OsrPass::OsrPass(const vk::Context& ctx, shaders::Id shader, Domain domain, uint32_t sceneFeatures,
                 bool sceneTexelFetch, std::vector<vk::SpecConstant> extraSpec)
    : domain_(domain),
      pipeline_(ctx, shader, osrDescriptorTypes(), sizeof(o::OsrPush),
                specs(ctx, sceneFeatures, sceneTexelFetch, std::move(extraSpec))) {}

void OsrPass::record(VkCommandBuffer cmd, const OsrBindings& bindings, o::OsrPush push,
                     uint32_t pixels) const {
  vk::Binder binder(pipeline_);
  bindings.fill(binder);
  if (domain_ == Domain::Pixels) {
    for (uint32_t first = 0; first < pixels; first += kMaxPixelsPerDispatch) {
      push.pixelOffset = first;
      push.pixelCount = std::min(kMaxPixelsPerDispatch, pixels - first);
      binder.bind(cmd, push);
      pipeline_.dispatch(cmd, vk::groupCount(push.pixelCount, o::kOsrWorkgroupSize));
    }
  } else if (push.mapCount > 0) {
    uint64_t items = domain_ == Domain::MapTexels ? uint64_t(push.mapCount) * gpu::hemi::kMapTexels
                                                  : uint64_t(push.mapCount);
    uint32_t x, y;
    nn::splitGroups(vk::groupCount(items, o::kOsrWorkgroupSize), x, y);
    binder.bind(cmd, push);
    pipeline_.dispatch(cmd, x, y);
  }
  vk::computeBarrier(cmd);
}

}  // namespace osr::oneshot
