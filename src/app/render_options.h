// The options of `osr-vk [options] scene.gltf` (the render command) read from the command line
// and cross-checked, before any file is read or any device made: what cmd_render.cpp runs on,
// and what tests/fuzz/fuzz_cli.cpp feeds arbitrary argument lists.
#pragma once
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "app/frames.h"
#include "app/integrators.h"
#include "app/scene_setup.h"
#include "vk/context.h"

namespace osr::app {

// The options of `osr-vk render`, as given.
struct RenderOptions {
  IntegratorOptions integrator;
  std::optional<std::string> exrPath, pngPath;  // --offline, --png
  std::optional<double> exposure, timeLimit;
  std::optional<long long> seed;
  SceneOptions scene;
  bool exrFloat = false, quiet = false;
  std::optional<std::string> dumpMaps, viewerScript, saveDir;
  std::optional<std::vector<long long>> crop;  // --crop X,Y,W,H
  std::optional<FrameOptions> frames;
  vk::ContextOptions device;
  std::string scenePath;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  bool live() const { return !exrPath && !pngPath; }  // no output file: the viewer
};

// Reads every render option and the one scene file; InputError on an unknown or malformed
// option (a bad --network model too: one line and exit 2 before any work).
RenderOptions parseRenderOptions(const std::vector<std::string>& args);

// The cross-checks that need no scene: the integrator's settings, and options that only shape
// an output which is not written (they would be ignored without a word). InputError naming the
// option otherwise. The viewer's display is the caller's to require.
IntegratorSettings checkRenderOptions(const RenderOptions& o);

}  // namespace osr::app
