// The scene a quality benchmark renders and the reference it is judged against: one of the
// reference scenes (cornell, room: their 4096-spp Cycles renders) or any glTF file with
// --reference, --env and --camera, as `osr-bench denoise` and `osr-bench osr-error` take them.
#pragma once
#include <memory>
#include <optional>
#include <string>

#include "app/args.h"
#include "bvh/bvh.h"
#include "image/image_io.h"
#include "render/denoiser.h"
#include "render/integrator.h"
#include "render/progressive_driver.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"
#include "vk/context.h"

namespace osr::bench {

struct SceneArgs {
  std::string name;       // --scene as given: cornell, room or a glTF path (JSON lines)
  std::string scene;      // the glTF file
  std::string reference;  // --reference, or the named scene's Cycles render
  std::optional<std::string> env;
  std::string camera;
};

// Reads --scene, --reference, --env and --camera; a glTF other than cornell or room needs
// --reference (InputError).
SceneArgs readSceneArgs(app::Args& a);

// The scene on the device with its BVH, the camera and the reference (InputError when the
// reference is not size x size).
struct BenchScene {
  BenchScene(const vk::Context& ctx, const SceneArgs& args, uint32_t size);
  scene::Scene host;
  scene::Camera camera;
  std::optional<scene::Environment> env;
  std::unique_ptr<scene::GpuScene> gpu;
  std::unique_ptr<bvh::Bvh> bvh;
  image::RgbImage reference;
  std::string referenceName;  // the reference's file name, for the JSON lines
  // What the reference's own noise adds to a relMSE against it, where the reference knows it:
  // from the spread of a merged reference's parts (image::referenceChannelNoise) or a raw
  // osr-vk render's variance layer (image::referenceNoise); Cycles' renders have neither.
  std::optional<double> referenceNoise;
  std::string referenceNoiseFrom;  // "spread" or "variance", the layer it came from
};

// --network as the quality benchmarks take it: default (the shipped model), none, or a packed
// file; the network alone (no filter).
render::DenoiseSettings networkSettings(const std::string& network);

// A render of at most maxUnits units, stopped after `seconds` when > 0, from seed's restart;
// its film resolved.
render::FilmLayers renderFilm(const vk::Context& ctx, render::Integrator& integrator,
                              const scene::Camera& cam, uint32_t seed, uint32_t maxUnits,
                              double seconds, render::RenderStats& stats);

}  // namespace osr::bench
