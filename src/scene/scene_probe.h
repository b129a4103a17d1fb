// The scene_probe pass: evaluates the GLSL surface accessors (surfaceAt, osrAlphaCutout) at a
// list of hit records. A G-buffer debugging tool, and the device half of the scene.glsl tests.
#pragma once
#include <vulkan/vulkan.h>

#include "scene/gpu_scene.h"
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

}  // namespace osr::scene
