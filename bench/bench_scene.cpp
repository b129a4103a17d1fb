#include "bench/bench_scene.h"

#include <filesystem>

#include "common/error.h"
#include "image/image_metrics.h"

namespace osr::bench {

SceneArgs readSceneArgs(app::Args& a) {
  SceneArgs s;
  s.name = s.scene = a.value("--scene").value_or("cornell");
  const auto referenceArg = a.value("--reference");
  s.env = a.value("--env");  // generated interiors light through their windows
  s.camera = a.value("--camera").value_or("");
  const bool named = s.scene == "cornell" || s.scene == "room";
  const std::string dir = std::string(OSR_SOURCE_DIR) + "/scenes/" + s.scene + "/";
  if (!named && !referenceArg)
    throw InputError("--scene " + s.scene + ": a scene other than cornell or room needs --reference FILE.exr");
  s.reference = referenceArg.value_or(dir + s.scene + "_cycles_4096spp.exr");
  if (named) s.scene = dir + s.scene + ".gltf";
  return s;
}

BenchScene::BenchScene(const vk::Context& ctx, const SceneArgs& args, uint32_t size)
    : host(scene::loadScene(args.scene)),
      camera(scene::selectCamera(host, args.camera, 1.f)),
      reference(image::readExrRgb(args.reference)) {
  if (reference.width != int(size) || reference.height != int(size))
    throw InputError("--reference " + args.reference + ": " + std::to_string(reference.width) +
                     "x" + std::to_string(reference.height) + ", the render is " +
                     std::to_string(size) + "x" + std::to_string(size) + " (--size)");
  referenceName = std::filesystem::path(args.reference).filename().string();
  // A merged reference (tools/merge_references.py) knows each channel's noise from the spread of
  // its parts; a raw render has its luminance variance. A denoised reference keeps its raw
  // colour as `noisy`: its variance is not its own colour's.
  const std::set<std::string> channels = image::exrChannels(args.reference);
  if (channels.count("spread.R")) {
    referenceNoise = image::referenceChannelNoise(reference, image::readExrRgb(args.reference, "spread"));
    referenceNoiseFrom = "spread";
  } else if (channels.count("variance.Y") && !channels.count("noisy.R")) {
    referenceNoise = image::referenceNoise(reference, image::readExrRgb(args.reference, "variance"));
    referenceNoiseFrom = "variance";
  }
  if (args.env) env = scene::loadEnvironment(*args.env);
  gpu = std::make_unique<scene::GpuScene>(ctx, host, env ? &*env : nullptr);
  bvh = std::make_unique<bvh::Bvh>(
      bvh::buildGpu(ctx, gpu->vertices, gpu->triangles, gpu->triangleCount));
}

render::DenoiseSettings networkSettings(const std::string& network) {
  render::DenoiseSettings s;
  if (network == "default") {
    s.network = render::DenoiseSettings::Network::Default;
  } else if (network != "none") {
    s.network = render::DenoiseSettings::Network::File;
    s.networkFile = network;
  }
  return s;
}

render::FilmLayers renderFilm(const vk::Context& ctx, render::Integrator& integrator,
                              const scene::Camera& cam, uint32_t seed, uint32_t maxUnits,
                              double seconds, render::RenderStats& stats) {
  render::DriverSettings ds;
  ds.maxUnits = maxUnits;
  ds.timeLimitS = seconds;
  render::ProgressiveDriver driver(ctx, integrator, ds);
  driver.restart(cam, seed);
  stats = driver.run();
  return integrator.resolve();
}

}  // namespace osr::bench
