// Probe passes over lib/scene.glsl: scene_probe evaluates the surface accessors (surfaceAt,
// osrAlphaCutout) at a list of hit records, scene_env_probe the environment functions at a list
// of directions and random numbers. Debugging tools, and the device half of the scene.glsl tests.
#pragma once
#include <vulkan/vulkan.h>

#include "scene/gpu_scene.h"
#include "shaders/shared/scene_env_probe.h"
#include "shaders/shared/scene_probe.h"
#include "vk/pipeline.h"

namespace osr::scene {

class SceneProbe {
 public:
  struct Args {
    const vk::Buffer* queries;  // gpu::scene_probe::Query[count]
    const vk::Buffer* results;  // gpu::scene_probe::Result[count]
    uint32_t count;
    const GpuScene* scene;
  };
  explicit SceneProbe(const vk::Context& ctx);
  // Records bind + dispatch + a barrier making the results visible to later passes/transfers.
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  vk::ComputePipeline pipeline_;
};

class EnvironmentProbe {
 public:
  struct Args {
    const vk::Buffer* queries;  // gpu::scene_env_probe::Query[count]
    const vk::Buffer* results;  // gpu::scene_env_probe::Result[count]
    uint32_t count;
    const GpuScene* scene;
  };
  explicit EnvironmentProbe(const vk::Context& ctx);
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  vk::ComputePipeline pipeline_;
};

}  // namespace osr::scene
