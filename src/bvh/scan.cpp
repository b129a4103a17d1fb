#include "bvh/scan.h"

#include <algorithm>

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

ExclusiveScan::ExclusiveScan(const vk::Context& ctx)
    : reduce_(ctx, shaders::Id::bvh_scan_reduce, bb::kScanBindingCount, sizeof(BuildPush)),
      top_(ctx, shaders::Id::bvh_scan_top, bb::kScanBindingCount, sizeof(BuildPush)),
      apply_(ctx, shaders::Id::bvh_scan_apply, bb::kScanBindingCount, sizeof(BuildPush)) {}

uint64_t ExclusiveScan::partialsBytes(uint32_t count) {
  return 4ull * std::max<uint64_t>(1, vk::groupCount(count, bb::kScanSegment));
}

void ExclusiveScan::record(VkCommandBuffer cmd, const Args& a) const {
  uint32_t segments = vk::groupCount(a.count, bb::kScanSegment);
  auto bind = [&](const vk::ComputePipeline& p) {
    vk::Binder(p)
        .set(bb::kScanBindingData, a.data)
        .set(bb::kScanBindingPartials, a.partials)
        .bind(cmd, push(a.count, segments));
  };
  bind(reduce_);
  reduce_.dispatch(cmd, groups(segments));
  vk::computeBarrier(cmd);
  bind(top_);
  top_.dispatch(cmd, 1);
  vk::computeBarrier(cmd);
  bind(apply_);
  apply_.dispatch(cmd, groups(segments));
  vk::computeBarrier(cmd);
}

}  // namespace osr::bvh
