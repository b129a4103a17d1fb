#include "app/scene_setup.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "common/error.h"

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
  const float requestedAspect = o.width && o.height ? float(*o.width) / float(*o.height) : 0.f;
  h.camera = scene::selectCamera(h.scene, o.camera, requestedAspect);
  if (o.env && *o.env != "none") {
    h.env = scene::loadEnvironment(*o.env);
  } else if (!o.env && !scene::hasLights(h.scene)) {
    // Most sample models carry no light: rendering them black for the whole budget helps no
    // one. Say so, and light them as a studio would.
    h.env = scene::neutralEnvironment();
    h.neutralSky = true;
  }
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

void applyCrop(HostScene& host, const std::vector<long long>& c) {
  if (c[0] + c[2] > host.width || c[1] + c[3] > host.height)
    throw InputError("--crop: " + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," +
                     std::to_string(c[2]) + "," + std::to_string(c[3]) + " is not inside the " +
                     std::to_string(host.width) + "x" + std::to_string(host.height) + " image");
  host.camera.window = {uint32_t(c[0]), uint32_t(c[1]), host.width, host.height};
  host.width = uint32_t(c[2]);
  host.height = uint32_t(c[3]);
}

void warnIfNeutralSky(const HostScene& host) {
  if (host.neutralSky)
    std::fprintf(stderr,
                 "osr-vk: warning: %s: the scene has no lights (no emissive surfaces, no "
                 "KHR_lights_punctual, no --env); lighting it with a neutral sky (--env none: "
                 "leave it unlit)\n",
                 host.scene.path.c_str());
}

DeviceScene::DeviceScene(const vk::Context& ctx, const HostScene& host)
    : gpu(ctx, host.scene, host.env ? &*host.env : nullptr),
      bvh(bvh::buildGpu(ctx, gpu.vertices, gpu.triangles, gpu.triangleCount)) {}

}  // namespace osr::app
