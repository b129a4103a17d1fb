// The BSDF test pass (shaders/pt_bsdf_probe.comp): evaluates or samples the path tracer's
// BSDF for a list of cases so tests can check shaders/lib/bsdf.glsl on the device it runs on.
#pragma once
#include <vector>

#include "shaders/shared/bsdf.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace osr::pt {

class BsdfProbe {
 public:
  explicit BsdfProbe(const vk::Context& ctx);

  struct Args {
    const vk::Buffer* cases = nullptr;  // gpu::bsdf::ProbeCase[push.caseCount]
    const vk::Buffer* out = nullptr;    // gpu::bsdf::ProbeOut[caseCount * per-case count]
    gpu::bsdf::ProbePush push{};
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

  // Convenience for tests: uploads cases, runs one pass, returns the outputs.
  std::vector<gpu::bsdf::ProbeOut> run(const std::vector<gpu::bsdf::ProbeCase>& cases,
                                       gpu::bsdf::ProbePush push) const;

 private:
  const vk::Context& ctx_;
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::pt
