// The live viewer: a GLFW window with a Vulkan swapchain on the renderer's own context, showing
// the film of a ProgressiveDriver as it refines, with an ImGui panel (layers, exposure, tone
// map, integrator settings, progress, timings, save) and camera controls. Rendering advances
// by one short driver step per frame (units sliced where the integrator allows), so the window
// keeps redrawing while the image refines; any camera or render-setting change restarts the
// refinement before the next step.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "image/image_io.h"
#include "render/denoiser.h"
#include "render/integrator.h"
#include "scene/scene.h"
#include "vk/context.h"

namespace osr::viewer {

// Keys, mouse and script, for --help.
extern const char* const kViewerHelp;

// A new integrator of `mode` for a width x height film, and its default unit budget.
struct IntegratorChoice {
  std::unique_ptr<render::Integrator> integrator;
  uint32_t defaultUnits = 64;
};
using IntegratorFactory =
    std::function<IntegratorChoice(const std::string& mode, uint32_t width, uint32_t height)>;

struct ViewerConfig {
  std::string scenePath;
  const scene::Scene* scene = nullptr;  // file cameras and bounds; outlives the viewer
  scene::Camera camera;                 // the starting (and reset) camera
  uint32_t width = 512, height = 512;   // render size; the window adds the panel
  std::vector<std::string> modes;       // integrators the factory makes
  std::string mode;                     // the starting one
  IntegratorFactory makeIntegrator;
  uint32_t maxUnits = 0;    // 0: the integrator's default
  double timeLimitS = 0.0;  // 0: none
  uint32_t seed = 0;
  std::optional<double> exposureEv;  // empty: automatic
  image::ToneMap toneMap = image::ToneMap::Clamp;
  std::string scriptPath;     // --viewer-script FILE (viewer_script.h); empty: none
  std::string saveDir = ".";  // S / the save buttons write here, never over a file
  render::DenoiseSettings denoise;  // --network / --filter: applied to the shown image
};

// The context must have been made with requireDisplay()'s instance extensions and
// swapchain = true. Returns the exit code (0 on Esc, window close or script quit).
int runViewer(const vk::Context& ctx, const ViewerConfig& config);

}  // namespace osr::viewer
