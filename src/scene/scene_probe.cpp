#include "scene/scene_probe.h"

namespace osr::scene {

namespace probe = osr::gpu::scene_probe;

SceneProbe::SceneProbe(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::scene_probe, probe::kBindingScene + gpu::kSceneBindingCount,
                sizeof(probe::Push)) {}

void SceneProbe::record(VkCommandBuffer cmd, const Args& args) const {
  static_assert(probe::kBindingQueries == 0 && probe::kBindingResults == 1 &&
                probe::kBindingScene == 2);
  auto buffers = args.scene->withBindings({*args.queries, *args.results});
  pipeline_.bindSpan(cmd, buffers, probe::Push{args.count});
  pipeline_.dispatch(cmd, vk::groupCount(args.count, probe::kWorkgroupSize));
  vk::computeBarrier(cmd);
}

namespace env_probe = osr::gpu::scene_env_probe;

EnvironmentProbe::EnvironmentProbe(const vk::Context& ctx)
    : pipeline_(ctx, shaders::Id::scene_env_probe,
                env_probe::kBindingScene + gpu::kSceneBindingCount, sizeof(env_probe::Push)) {}

void EnvironmentProbe::record(VkCommandBuffer cmd, const Args& args) const {
  static_assert(env_probe::kBindingQueries == 0 && env_probe::kBindingResults == 1 &&
                env_probe::kBindingScene == 2);
  auto buffers = args.scene->withBindings({*args.queries, *args.results});
  pipeline_.bindSpan(cmd, buffers, env_probe::Push{args.count});
  pipeline_.dispatch(cmd, vk::groupCount(args.count, env_probe::kWorkgroupSize));
  vk::computeBarrier(cmd);
}

}  // namespace osr::scene
