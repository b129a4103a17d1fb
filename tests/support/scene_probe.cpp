#include "support/scene_probe.h"

#include "vk/binder.h"

namespace osr::scene {

namespace probe = osr::gpu::scene_probe;
namespace env_probe = osr::gpu::scene_env_probe;

// The two shaders must agree on everything this class assumes.
static_assert(env_probe::kBindingQueries == probe::kBindingQueries &&
              env_probe::kBindingResults == probe::kBindingResults &&
              env_probe::kBindingScene == probe::kBindingScene);
static_assert(env_probe::kWorkgroupSize == probe::kWorkgroupSize &&
              sizeof(env_probe::Push) == sizeof(probe::Push));

SceneProbe::SceneProbe(const vk::Context& ctx, ProbeKind kind)
    : pipeline_(
          ctx, kind == ProbeKind::Surface ? shaders::Id::scene_probe : shaders::Id::scene_env_probe,
          probe::kBindingScene + gpu::kSceneBindingCount, sizeof(probe::Push)) {}

void SceneProbe::record(VkCommandBuffer cmd, const Args& args) const {
  vk::Binder binder(pipeline_);
  binder.set(probe::kBindingQueries, *args.queries).set(probe::kBindingResults, *args.results);
  args.scene->bind(binder, probe::kBindingScene);
  binder.bind(cmd, probe::Push{args.count});
  pipeline_.dispatch(cmd, vk::groupCount(args.count, probe::kWorkgroupSize));
  vk::computeBarrier(cmd);
}

}  // namespace osr::scene
