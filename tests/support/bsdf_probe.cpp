#include "support/bsdf_probe.h"

#include <algorithm>

#include "vk/binder.h"

namespace osr::pt {

namespace probe = gpu::bsdf;

namespace {
uint64_t outputsPerCase(const probe::ProbePush& push) {
  if (push.mode == probe::kProbeEval) return uint64_t(push.thetaCount) * push.phiCount;
  return push.mode == probe::kProbeGuide ? 1u : push.samplesPerCase;
}
}  // namespace

BsdfProbe::BsdfProbe(const vk::Context& ctx)
    : ctx_(ctx), pipeline_(ctx, shaders::Id::pt_bsdf_probe, probe::kProbeBindingCount, sizeof(probe::ProbePush)) {}

void BsdfProbe::record(VkCommandBuffer cmd, const Args& a) const {
  uint64_t items = outputsPerCase(a.push) * a.push.caseCount;
  uint32_t groups = vk::groupCount(items, probe::kProbeWorkgroupSize);
  // 2-D dispatch: at most 65535 groups per dimension on every device.
  uint32_t x = std::min<uint32_t>(groups, 65535u);
  uint32_t y = (groups + x - 1) / x;
  vk::Binder(pipeline_)
      .set(probe::kProbeBindingCases, *a.cases)
      .set(probe::kProbeBindingOut, *a.out)
      .bind(cmd, a.push);
  pipeline_.dispatch(cmd, x, y);
  vk::computeBarrier(cmd);
}

std::vector<probe::ProbeOut> BsdfProbe::run(const std::vector<probe::ProbeCase>& cases,
                                            probe::ProbePush push) const {
  push.caseCount = static_cast<uint32_t>(cases.size());
  uint64_t count = outputsPerCase(push) * cases.size();
  vk::Buffer caseBuf(ctx_, cases.size() * sizeof(probe::ProbeCase), vk::MemoryUse::DeviceLocal,
                     "bsdf probe cases");
  caseBuf.uploadVector(cases);
  vk::Buffer outBuf(ctx_, count * sizeof(probe::ProbeOut), vk::MemoryUse::DeviceLocal,
                    "bsdf probe out");
  ctx_.submitAndWait([&](VkCommandBuffer cmd) { record(cmd, {&caseBuf, &outBuf, push}); });
  return outBuf.downloadVector<probe::ProbeOut>(count);
}

}  // namespace osr::pt
