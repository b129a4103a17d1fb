#include "app/scene_setup.h"

#include <algorithm>
#include <cmath>

namespace osr::app {

SceneOptions readSceneOptions(Args& args) {
  SceneOptions o;
  o.camera = args.value("--camera").value_or("");
  o.env = args.value("--env");
  o.width = args.integer("--width", 1, 16384);
  o.height = args.integer("--height", 1, 16384);
  return o;
}

HostScene loadHostScene(const std::string& path, const SceneOptions& o) {
  HostScene h;
  h.scene = scene::loadScene(path);
  if (o.env) h.env = scene::loadEnvironment(*o.env);
  const float requestedAspect = o.width && o.height ? float(*o.width) / float(*o.height) : 0.f;
  h.camera = scene::selectCamera(h.scene, o.camera, requestedAspect);
  const float aspect = h.camera.aspect > 0.f ? h.camera.aspect : 1.f;
  if (o.width && o.height) {
    h.width = uint32_t(*o.width);
    h.height = uint32_t(*o.height);
  } else if (o.height) {
    h.height = uint32_t(*o.height);
    h.width = std::max(1u, uint32_t(std::lround(*o.height * aspect)));
  } else {
    h.width = o.width ? uint32_t(*o.width) : 512u;
    h.height = std::max(1u, uint32_t(std::lround(h.width / aspect)));
  }
  return h;
}

DeviceScene::DeviceScene(const vk::Context& ctx, const HostScene& host)
    : gpu(ctx, host.scene, host.env ? &*host.env : nullptr),
      bvh(bvh::buildGpu(ctx, gpu.vertices, gpu.triangles, gpu.triangleCount)) {}

}  // namespace osr::app
