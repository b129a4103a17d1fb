#include "render/trace_pass.h"

#include <algorithm>
#include <vector>

namespace osr::render {

namespace pt = gpu::pt;

static_assert(pt::kPtSceneBinding == pt::kPtBvhBinding + gpu::bvh::kBvhBindingCount);
static_assert(pt::kPtBindingCount == pt::kPtSceneBinding + gpu::scene::kSceneBindingCount);

TracePass::TracePass(const vk::Context& ctx, uint32_t integrator)
    : pipeline_(ctx, shaders::Id::pt_trace, pt::kPtBindingCount, sizeof(pt::Push),
                {vk::specUint(pt::kPtSpecIntegrator, integrator)}) {}

void TracePass::record(VkCommandBuffer cmd, const Args& a) const {
  std::vector<vk::BufferRange> buffers = {a.film->buffer(), *a.frame};
  for (const vk::BufferRange& r : a.bvh->bindings()) buffers.push_back(r);
  for (const vk::BufferRange& r : a.scene->bindings()) buffers.push_back(r);
  const uint32_t pixels = a.film->pixelCount();
  for (uint32_t done = 0; done < a.sampleCount;) {
    const uint32_t samples = std::min(kMaxSamplesPerDispatch, a.sampleCount - done);
    for (uint32_t first = 0; first < pixels; first += kMaxPixelsPerDispatch) {
      pt::Push push{first, std::min(kMaxPixelsPerDispatch, pixels - first), a.sampleIndex + done,
                    samples};
      pipeline_.bindSpan(cmd, buffers, push);
      pipeline_.dispatch(cmd, vk::groupCount(push.pixelCount, pt::kPtWorkgroupSize));
      vk::computeBarrier(cmd);
    }
    done += samples;
  }
}

}  // namespace osr::render
