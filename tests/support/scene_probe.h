// Probe passes over lib/scene.glsl: scene_probe evaluates the surface accessors (surfaceAt,
// osrAlphaCutout) at a list of hit records, scene_env_probe the environment functions at a list
// of directions and random numbers. Debugging tools, and the device half of the scene.glsl tests.
// Both shaders share one layout (queries, results, then the scene; Push{count}), so one class
// records either.
#pragma once
#include <vulkan/vulkan.h>

#include "scene_gpu/gpu_scene.h"
#include "shaders/shared/scene_env_probe.h"
#include "shaders/shared/scene_probe.h"
#include "vk/pipeline.h"

namespace osr::scene {

enum class ProbeKind {
  Surface,     // scene_probe: gpu::scene_probe::Query -> Result
  Environment  // scene_env_probe: gpu::scene_env_probe::Query -> Result
};

class SceneProbe {
 public:
  struct Args {
    const vk::Buffer* queries;  // Query[count] of the kind's header
    const vk::Buffer* results;  // Result[count]
    uint32_t count;
    const GpuScene* scene;
  };
  SceneProbe(const vk::Context& ctx, ProbeKind kind);
  // Records bind + dispatch + a barrier making the results visible to later passes/transfers.
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::scene
