// What render and maps share before their own work: the scene options (--camera, --env,
// --width, --height), loading the scene and choosing the camera and image size on the host,
// then uploading it and building the BVH on the device.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/args.h"
#include "bvh/bvh.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"
#include "vk/context.h"

namespace osr::app {

struct SceneOptions {
  std::string camera;              // --camera N|name ("" = default)
  std::optional<std::string> env;  // --env file.exr|.hdr|none
  std::optional<long long> width, height;
};

// Consumes --camera, --env, --width and --height from `args`.
SceneOptions readSceneOptions(Args& args);

// The scene on the host with its camera and image size: --width and --height as given, one of
// them from the camera's aspect, or 512 wide by default. A scene without lights and without
// --env gets scene::neutralEnvironment() (neutralSky); --env none leaves it unlit.
struct HostScene {
  scene::Scene scene;
  std::optional<scene::Environment> env;
  scene::Camera camera;
  uint32_t width = 0, height = 0;
  bool neutralSky = false;  // env is scene::neutralEnvironment(): the scene has no lights
};
HostScene loadHostScene(const std::string& path, const SceneOptions& options);
// --crop X,Y,W,H: the render's film becomes that window of host's image (scene::Camera::Window),
// so that it renders the whole image's pixels there; host.width x height becomes W x H.
// A window not inside the image is an InputError.
void applyCrop(HostScene& host, const std::vector<long long>& xywh);
// The one-line warning for a neutral sky, on stderr: printed once the command's own checks
// have passed, so that a refused command prints only its error.
void warnIfNeutralSky(const HostScene& host);

// The host scene on the device, with its BVH.
struct DeviceScene {
  DeviceScene(const vk::Context& ctx, const HostScene& host);
  scene::GpuScene gpu;
  bvh::Bvh bvh;
};

}  // namespace osr::app
