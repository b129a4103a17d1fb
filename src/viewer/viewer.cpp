#include "viewer/viewer.h"

#include <malloc.h>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <utility>

#include "common/error.h"
#include "render/film_export.h"
#include "render/progressive_driver.h"
#include "viewer/camera_controller.h"
#include "viewer/coarse_start.h"
#include "viewer/imgui_layer.h"
#include "viewer/presenter.h"
#include "viewer/viewer_script.h"
#include "viewer/window.h"

namespace osr::viewer {

const char* const kViewerHelp =
    "viewer (without --offline/--png): a window showing the render as it refines\n"
    "  mouse: left drag orbit, middle drag (or shift + left) pan, wheel zoom,\n"
    "         right drag look around; with the right button held W/A/S/D fly, Q/E down/up\n"
    "  keys:  S save EXR (all layers) + PNG (as shown), Space pause/resume,\n"
    "         1-6 layer (combined, direct, indirect, albedo, normal, depth),\n"
    "         +/- exposure by 1/2 EV (switches to manual), F frame the scene, Esc quit\n"
    "  any camera or render-setting change restarts the refinement at once\n"
    "  --viewer-script FILE  timed camera moves, key presses and screenshots (docs/viewer.md)\n"
    "  --save-dir DIR        existing folder where S and the save buttons write (default:\n"
    "                        the current one)\n";

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kPanelWidth = 320;
constexpr int kMinRenderSize = 16;
// While the render refines the film is downloaded and tone mapped at most this often (it
// costs about a UI frame on lavapipe); at once for the first slice and the first complete
// unit after a restart, and for the last unit.
constexpr double kResolveIntervalS = 0.25;
// With --network or --filter, the shown image is denoised at most once per this many times the
// denoiser's own last run, so denoising takes at most a fifth of the time between images:
// the a-trous filter (0.1 s at 256 x 256 on lavapipe) every 0.5 s, the network about every 1.5 s.
constexpr double kDenoiseCostShare = 5.0;
// ... or sooner, once the units have doubled since the shown image: early after a move each
// doubling halves the noise, which is worth the denoiser's time, and there are few of them
// (1, 2, 4, 8, ... units: at most a handful in the first seconds).
constexpr uint32_t kDenoiseUnitGrowth = 2;
// Freed heap memory goes back to the system this often. The heap otherwise keeps what the
// viewer's many short-lived blocks (validation-layer and driver bookkeeping, resolves) freed:
// a loaded 4-minute soak held 250 MB in use in a 480 MB heap, and how much of the free part
// stayed resident depended on timing (docs/benchmarks.md, "soak").
constexpr double kHeapTrimIntervalS = 2.0;
// Submissions this long keep the window above 20 redraws a second with the UI's own work.
constexpr double kStepTargetS = 0.015;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Per-frame pacing while the render refines (not paused, not finished).
struct Pacing {
  std::vector<double> frameMs;
  std::vector<double> moveToImageMs;     // to the first slice of the new view on screen
  std::vector<double> moveToCompleteMs;  // to its first complete unit on screen
  double renderingS = 0.0;
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5))];
}

class Viewer {
 public:
  Viewer(const vk::Context& ctx, const ViewerConfig& config, std::vector<ScriptCommand> script);
  int run();

 private:
  // Rendering.
  void makeIntegrator(const std::string& mode, uint32_t width, uint32_t height);
  void requestRestart();
  void stepRender();
  void refreshImage();
  void retonemap();
  // Frame.
  void handleResize();
  void composeFrame(uint8_t* pixels);
  void drawPanel();
  // Input.
  void onKey(int key, int mods);
  void pollMouseAndFly(double dt);
  bool runScript();
  void save(bool exr, bool png);
  void printStats() const;
  bool rendering() const { return !paused_ && !driver_->finished(); }

  static void keyCallback(GLFWwindow* w, int key, int scancode, int action, int mods);
  static void scrollCallback(GLFWwindow* w, double dx, double dy);

  const vk::Context& ctx_;
  ViewerConfig config_;
  std::vector<ScriptCommand> script_;
  size_t scriptNext_ = 0;
  Clock::time_point opened_, scriptMark_;
  Window window_;
  Presenter presenter_;
  ImGuiLayer imgui_;
  CameraController camera_;

  std::string mode_;
  std::unique_ptr<render::Integrator> integrator_;
  std::unique_ptr<render::ProgressiveDriver> driver_;
  uint32_t renderWidth_, renderHeight_;
  // The first images after a restart, coarse, until the film has a whole unit.
  CoarseStart coarse_;
  bool coarseChanged_ = false;  // a coarse sample landed since the last resolve
  bool coarseShown_ = false;    // the image on screen is the coarse one
  int targetUnits_ = 0;         // panel edits, applied by restart
  float timeLimit_ = 0.f;
  int seed_ = 0;
  bool restartPending_ = true;
  bool paused_ = false;
  bool quit_ = false;

  // What is on screen: the last resolved film, its tone mapped layer, and its unit count.
  render::FilmLayers film_;
  std::vector<uint8_t> shown_;  // RGB8, renderWidth_ x renderHeight_ of the film it came from
  int shownWidth_ = 0, shownHeight_ = 0;
  uint64_t shownVersion_ = 1;  // changes with shown_; composed[slot] says what each slot holds
  std::pair<uint64_t, uint64_t> composed_[Presenter::kFramesInFlight] = {};
  uint32_t shownUnits_ = 0;
  bool shownFinal_ = false;  // the image of a finished render
  bool filmChanged_ = false;
  Clock::time_point lastResolve_;
  Clock::time_point lastHeapTrim_ = Clock::now();
  double heapTrimMsMax_ = 0.0;  // the longest malloc_trim, in the stats line
  // --network / --filter: the shown film is denoised (paced by kDenoiseCostShare).
  std::unique_ptr<render::Denoiser> denoiser_;
  render::Layer layer_ = render::Layer::Combined;
  bool autoExposure_ = true;
  float exposureEv_ = 0.f;  // manual EV, or the last automatic one for display
  image::ToneMap toneMap_ = image::ToneMap::Clamp;

  // Input state.
  std::deque<std::pair<int, int>> keys_;  // (key, mods) pressed since the last frame
  double scroll_ = 0.0;
  double lastX_ = 0.0, lastY_ = 0.0;
  bool dragging_[3] = {false, false, false};
  std::string pendingScreenshot_;
  int pendingResizeW_ = 0, pendingResizeH_ = 0;
  Clock::time_point resizeAsked_;

  // Messages and measurements.
  std::string status_;
  Pacing pacing_;
  std::optional<Clock::time_point> moveTime_;  // a restart whose first image is not shown yet
  bool countLatency_ = false;
  uint32_t restarts_ = 0;  // refinements started, the first included
  bool firstMoveShown_ = false;
  double lastMoveToCompleteMs_ = 0.0;
  double lastMoveToImageMs_ = 0.0;
  double uiFps_ = 0.0;
};

Viewer::Viewer(const vk::Context& ctx, const ViewerConfig& config,
               std::vector<ScriptCommand> script)
    : ctx_(ctx),
      config_(config),
      script_(std::move(script)),
      window_(int(config.width) + kPanelWidth, int(config.height),
              "osr-vk - " + std::filesystem::path(config.scenePath).filename().string()),
      presenter_(ctx,
                 window_.createSurface(ctx.instance(), ctx.physicalDevice(), ctx.queueFamily()),
                 VkExtent2D{config.width + kPanelWidth, config.height}),
      imgui_(ctx, window_, presenter_),
      camera_(config.camera, config.scene->boundsMin, config.scene->boundsMax),
      renderWidth_(config.width),
      renderHeight_(config.height),
      coarse_(ctx, config.makeIntegrator, config.denoise, kStepTargetS) {
  glfwSetWindowUserPointer(window_.handle(), this);
  // ImGui installed its callbacks first and would chain to none; ours chain to ImGui's.
  static GLFWkeyfun imguiKey = nullptr;
  static GLFWscrollfun imguiScroll = nullptr;
  imguiKey = glfwSetKeyCallback(window_.handle(), nullptr);
  imguiScroll = glfwSetScrollCallback(window_.handle(), nullptr);
  glfwSetKeyCallback(window_.handle(), [](GLFWwindow* w, int key, int sc, int action, int mods) {
    if (imguiKey) imguiKey(w, key, sc, action, mods);
    keyCallback(w, key, sc, action, mods);
  });
  glfwSetScrollCallback(window_.handle(), [](GLFWwindow* w, double dx, double dy) {
    if (imguiScroll) imguiScroll(w, dx, dy);
    scrollCallback(w, dx, dy);
  });
  if (config.exposureEv) autoExposure_ = false, exposureEv_ = float(*config.exposureEv);
  toneMap_ = config.toneMap;
  timeLimit_ = float(config.timeLimitS);
  seed_ = int(config.seed);
  makeIntegrator(config.mode, renderWidth_, renderHeight_);
  if (config.maxUnits) targetUnits_ = int(config.maxUnits);
  opened_ = scriptMark_ = Clock::now();
}

void Viewer::keyCallback(GLFWwindow* w, int key, int, int action, int mods) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (self && action == GLFW_PRESS) self->keys_.push_back({key, mods});
}

void Viewer::scrollCallback(GLFWwindow* w, double, double dy) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (self) self->scroll_ += dy;
}

void Viewer::makeIntegrator(const std::string& mode, uint32_t width, uint32_t height) {
  driver_.reset();
  integrator_.reset();
  // The old integrator's host memory goes back to the system: freed small blocks between
  // long-lived ones otherwise stay resident (a soak grew 7 % with the fixed mmap threshold
  // alone; docs/benchmarks.md, "soak").
  malloc_trim(0);
  IntegratorChoice choice = config_.makeIntegrator(mode, width, height);
  integrator_ = std::move(choice.integrator);
  if (mode != mode_) targetUnits_ = int(choice.defaultUnits);
  mode_ = mode;
  renderWidth_ = width;
  renderHeight_ = height;
  requestRestart();
}

void Viewer::requestRestart() {
  restartPending_ = true;
  // Latency runs from the oldest move not yet answered by an image on screen.
  if (!moveTime_ || firstMoveShown_) moveTime_ = Clock::now(), firstMoveShown_ = false;
}

void Viewer::stepRender() {
  if (restartPending_) {
    render::DriverSettings ds;
    ds.maxUnits = uint32_t(std::max(1, targetUnits_));
    ds.timeLimitS = double(std::max(0.f, timeLimit_));
    ds.batchTargetS = kStepTargetS;
    ds.sliceUnits = true;
    // The same driver keeps its measured unit time, so even the first unit after a camera
    // move is sliced; a new integrator or budget needs a new one.
    if (!driver_ || &driver_->integrator() != integrator_.get() ||
        driver_->settings().maxUnits != ds.maxUnits ||
        driver_->settings().timeLimitS != ds.timeLimitS)
      driver_ = std::make_unique<render::ProgressiveDriver>(ctx_, *integrator_, ds);
    driver_->restart(camera_.camera(), uint32_t(seed_));
    // The preview's own first sample is as quick as a coarse one.
    if (mode_ != "preview")
      coarse_.restart(camera_.camera(), uint32_t(seed_), renderWidth_, renderHeight_);
    else
      coarse_.cancel();
    coarseChanged_ = coarseShown_ = false;
    ++restarts_;
    restartPending_ = false;
    paused_ = false;
    shownFinal_ = false;
    filmChanged_ = false;
    shownUnits_ = 0;
  }
  if (!rendering()) return;
  if (coarse_.running()) {
    if (coarse_.step()) coarseChanged_ = true;
    return;
  }
  if (driver_->step()) filmChanged_ = true;
}

void Viewer::refreshImage() {
  const render::Progress p = driver_->progress();
  // Each coarse sample is shown at once, until the film has a whole unit.
  if (coarseChanged_ && p.units == 0) {
    coarse_.resolveInto(film_);
    lastResolve_ = Clock::now();
    coarseChanged_ = false;
    coarseShown_ = true;
    shownUnits_ = 0;
    shownFinal_ = false;
    retonemap();
    return;
  }
  if (!filmChanged_ || (coarseShown_ && p.units == 0)) return;
  // Without a coarse image, shown as soon as the first slice after a restart lands: the new
  // view fills in band by band over black (pixels without a sample resolve to 0), never over
  // the old view.
  const bool first =
      (moveTime_ && !firstMoveShown_) || (p.units >= 1 && shownUnits_ == 0) || coarseShown_;
  if (!first && !driver_->finished() && secondsSince(lastResolve_) < kResolveIntervalS) return;
  // Denoised progressively, after each new complete unit as long as the denoiser's time stays
  // a small share of the render's (the network costs about a unit's time on lavapipe), or
  // once the units doubled.
  if (config_.denoise.active() && !first && !driver_->finished() &&
      (p.units <= shownUnits_ ||
       (denoiser_ && secondsSince(lastResolve_) < kDenoiseCostShare * denoiser_->lastSeconds() &&
        p.units < kDenoiseUnitGrowth * shownUnits_)))
    return;
  // Into the same layers each time: a new set per resolve (25 MiB at 512 x 512, many a
  // second) left the heap fragmented over a long session (docs/benchmarks.md, "soak").
  integrator_->resolveInto(film_);
  if (config_.denoise.active()) {
    if (!denoiser_ || denoiser_->width() != uint32_t(film_.width) ||
        denoiser_->height() != uint32_t(film_.height))
      denoiser_ =
          std::make_unique<render::Denoiser>(ctx_, config_.denoise, film_.width, film_.height);
    denoiser_->apply(film_);
  }
  lastResolve_ = Clock::now();
  filmChanged_ = false;
  coarseShown_ = false;
  shownUnits_ = p.units;
  shownFinal_ = driver_->finished();
  retonemap();
}

void Viewer::retonemap() {
  if (film_.width == 0) return;
  const image::RgbImage img = render::layerImage(film_, layer_);
  const bool colour = layer_ != render::Layer::Normal && layer_ != render::Layer::Depth;
  double ev = 0.0;
  if (colour) {
    if (autoExposure_) exposureEv_ = float(image::autoExposureEv(img));
    ev = exposureEv_;
  }
  shown_ = image::toneMapSrgb8(img, ev, colour ? toneMap_ : image::ToneMap::Clamp);
  ++shownVersion_;
  shownWidth_ = img.width;
  shownHeight_ = img.height;
}

void Viewer::handleResize() {
  int w = 0, h = 0;
  window_.framebufferSize(w, h);
  while ((w == 0 || h == 0) && !window_.shouldClose()) {  // minimised: nothing to draw
    glfwWaitEvents();
    window_.framebufferSize(w, h);
  }
  const VkExtent2D e = presenter_.extent();
  if (uint32_t(w) == e.width && uint32_t(h) == e.height) return;
  presenter_.resize({uint32_t(w), uint32_t(h)});
  const VkExtent2D got = presenter_.extent();
  const uint32_t rw = uint32_t(std::max(kMinRenderSize, int(got.width) - kPanelWidth));
  const uint32_t rh = uint32_t(std::max(kMinRenderSize, int(got.height)));
  if (rw != renderWidth_ || rh != renderHeight_) makeIntegrator(mode_, rw, rh);
}

void Viewer::composeFrame(uint8_t* px) {
  // A slot's staging pixels survive until it is reused: rewrite only what changed.
  const std::pair<uint64_t, uint64_t> now{shownVersion_, presenter_.stagingGeneration()};
  if (composed_[presenter_.slot()] == now) return;
  composed_[presenter_.slot()] = now;
  const VkExtent2D e = presenter_.extent();
  const bool bgra = presenter_.bgra();
  // Background (also behind the panel, which ImGui draws over it).
  for (size_t i = 0; i < size_t(e.width) * e.height; ++i) {
    px[4 * i + 0] = px[4 * i + 1] = px[4 * i + 2] = 24;
    px[4 * i + 3] = 255;
  }
  const int w = std::min<int>(shownWidth_, int(e.width)),
            h = std::min<int>(shownHeight_, int(e.height));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t* s = &shown_[(size_t(y) * shownWidth_ + x) * 3];
      uint8_t* d = &px[(size_t(y) * e.width + x) * 4];
      d[0] = s[bgra ? 2 : 0];
      d[1] = s[1];
      d[2] = s[bgra ? 0 : 2];
    }
}

void Viewer::onKey(int key, int mods) {
  switch (key) {
    case GLFW_KEY_ESCAPE:
      quit_ = true;
      break;
    case GLFW_KEY_SPACE:
      paused_ = !paused_;
      break;
    case GLFW_KEY_S:
      save(true, true);
      break;
    case GLFW_KEY_F:
      camera_.frame();
      requestRestart();
      break;
    case GLFW_KEY_EQUAL:  // '+' is shift + '=' on US layouts; '=' alone works too
    case GLFW_KEY_KP_ADD:
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: {
      const bool up = key == GLFW_KEY_EQUAL || key == GLFW_KEY_KP_ADD;
      autoExposure_ = false;
      exposureEv_ += up ? 0.5f : -0.5f;
      retonemap();
      break;
    }
    default:
      if (key >= GLFW_KEY_1 && key <= GLFW_KEY_6) {
        layer_ = render::Layer(key - GLFW_KEY_1);
        retonemap();
      }
  }
  (void)mods;
}

void Viewer::pollMouseAndFly(double dt) {
  const ImGuiIO& io = ImGui::GetIO();
  double x = 0.0, y = 0.0;
  glfwGetCursorPos(window_.handle(), &x, &y);
  const double dx = x - lastX_, dy = y - lastY_;
  lastX_ = x, lastY_ = y;
  GLFWwindow* w = window_.handle();
  const bool inImage = x < double(renderWidth_) && y < double(renderHeight_);
  for (int b = 0; b < 3; ++b) {
    const bool down = glfwGetMouseButton(w, b) == GLFW_PRESS;
    if (!down)
      dragging_[b] = false;
    else if (!dragging_[b] && inImage && !io.WantCaptureMouse)
      dragging_[b] = true;
  }
  const bool shift = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                     glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
  bool moved = false;
  if ((dx != 0.0 || dy != 0.0)) {
    if (dragging_[GLFW_MOUSE_BUTTON_LEFT] && !shift) {
      camera_.orbit(float(dx) * 0.25f, float(dy) * 0.25f);
      moved = true;
    } else if (dragging_[GLFW_MOUSE_BUTTON_MIDDLE] ||
               (dragging_[GLFW_MOUSE_BUTTON_LEFT] && shift)) {
      camera_.pan(-float(dx) / float(renderHeight_), float(dy) / float(renderHeight_));
      moved = true;
    } else if (dragging_[GLFW_MOUSE_BUTTON_RIGHT]) {
      camera_.look(float(dx) * 0.2f, -float(dy) * 0.2f);
      moved = true;
    }
  }
  if (scroll_ != 0.0 && !io.WantCaptureMouse && inImage) {
    camera_.zoom(float(std::pow(0.9, scroll_)));
    moved = true;
  }
  scroll_ = 0.0;
  if (dragging_[GLFW_MOUSE_BUTTON_RIGHT] && !io.WantCaptureKeyboard) {
    const auto held = [&](int k) { return glfwGetKey(w, k) == GLFW_PRESS ? 1.f : 0.f; };
    const float speed = 0.5f * float(std::min(dt, 0.1));  // scene radii per second x seconds
    const float f = held(GLFW_KEY_W) - held(GLFW_KEY_S), r = held(GLFW_KEY_D) - held(GLFW_KEY_A),
                u = held(GLFW_KEY_E) - held(GLFW_KEY_Q);
    if (f != 0.f || r != 0.f || u != 0.f) {
      camera_.fly(f * speed, r * speed, u * speed);
      moved = true;
    }
  }
  if (moved) requestRestart();
}

bool Viewer::runScript() {
  while (scriptNext_ < script_.size()) {
    const ScriptCommand& c = script_[scriptNext_];
    const auto& n = c.numbers;
    if (c.name == "at" && secondsSince(opened_) < n[0]) return true;
    if (c.name == "wait" && secondsSince(scriptMark_) < n[0]) return true;
    if (c.name == "wait-units" && (restartPending_ || moveTime_ || shownUnits_ < uint32_t(n[0])))
      return true;
    if (c.name == "wait-done" && (restartPending_ || !shownFinal_)) return true;
    if (c.name == "wait-image" && (restartPending_ || (moveTime_ && !firstMoveShown_))) return true;
    if (c.name == "resize") {
      int w = 0, h = 0;
      window_.framebufferSize(w, h);
      if (pendingResizeW_ == 0) {
        pendingResizeW_ = int(n[0]), pendingResizeH_ = int(n[1]);
        resizeAsked_ = Clock::now();
        window_.resize(pendingResizeW_, pendingResizeH_);
        return true;
      }
      if (w != pendingResizeW_ || h != pendingResizeH_ ||
          presenter_.extent().width != uint32_t(w) || presenter_.extent().height != uint32_t(h)) {
        if (secondsSince(resizeAsked_) > 10.0)
          throw InputError(config_.scriptPath + ":" + std::to_string(c.line) +
                           ": the window system did not resize the window");
        return true;
      }
      pendingResizeW_ = pendingResizeH_ = 0;
    }
    if (c.name == "screenshot") {
      // Taken at the end of this frame: later commands wait for the next one, so the
      // screenshot shows the state the commands before it left.
      pendingScreenshot_ = c.text;
      scriptMark_ = Clock::now();
      ++scriptNext_;
      return true;
    }
    if (c.name == "key") {
      static const std::pair<const char*, int> kNames[] = {
          {"s", GLFW_KEY_S},         {"space", GLFW_KEY_SPACE}, {"1", GLFW_KEY_1},
          {"2", GLFW_KEY_2},         {"3", GLFW_KEY_3},         {"4", GLFW_KEY_4},
          {"5", GLFW_KEY_5},         {"6", GLFW_KEY_6},         {"plus", GLFW_KEY_EQUAL},
          {"minus", GLFW_KEY_MINUS}, {"f", GLFW_KEY_F},         {"escape", GLFW_KEY_ESCAPE}};
      for (auto [name, key] : kNames)
        if (c.text == name) onKey(key, 0);
    }
    if (c.name == "orbit") camera_.orbit(float(n[0]), float(n[1])), requestRestart();
    if (c.name == "pan") camera_.pan(float(n[0]), float(n[1])), requestRestart();
    if (c.name == "zoom") camera_.zoom(float(n[0])), requestRestart();
    if (c.name == "fly") camera_.fly(float(n[0]), float(n[1]), float(n[2])), requestRestart();
    if (c.name == "camera") {
      if (size_t(n[0]) >= config_.scene->cameras.size())
        throw InputError(config_.scriptPath + ":" + std::to_string(c.line) + ": the scene has " +
                         std::to_string(config_.scene->cameras.size()) + " camera(s)");
      camera_.set(config_.scene->cameras[size_t(n[0])]);
      requestRestart();
    }
    if (c.name == "reset") camera_.set(config_.camera), requestRestart();
    if (c.name == "mode" && c.text != mode_) makeIntegrator(c.text, renderWidth_, renderHeight_);
    if (c.name == "stats") printStats();
    if (c.name == "quit") quit_ = true;
    scriptMark_ = Clock::now();
    ++scriptNext_;
  }
  return false;
}

void Viewer::save(bool exr, bool png) {
  if (film_.width == 0) {
    status_ = "nothing to save yet";
    return;
  }
  namespace fs = std::filesystem;
  const std::string stem = fs::path(config_.scenePath).stem().string();
  // The first number free for both extensions: saving never replaces a file.
  for (int n = 1; n < 100000; ++n) {
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, "-%03d", n);
    const fs::path base = fs::path(config_.saveDir) / (stem + suffix);
    const std::string exrPath = base.string() + ".exr", pngPath = base.string() + ".png";
    if (fs::exists(exrPath) || fs::exists(pngPath)) continue;
    try {
      // The EXR holds every layer as --offline writes it; the PNG is what the window shows.
      if (exr) image::writeExr(exrPath, render::toLayeredImage(film_), image::ExrPixelType::Half);
      if (png) image::writePng8(pngPath, shownWidth_, shownHeight_, shown_);
      status_ = "saved " + (exr ? exrPath : pngPath) + (exr && png ? " and .png" : "");
    } catch (const InputError& e) {
      status_ = std::string("save failed: ") + e.what();
    }
    std::fprintf(stderr, "osr-vk: %s\n", status_.c_str());
    return;
  }
}

void Viewer::printStats() const {
  // A percentile of no samples is null, not 0.
  const auto pct = [](const std::vector<double>& v, double q) {
    char buf[32];
    if (v.empty()) return std::string("null");
    std::snprintf(buf, sizeof buf, "%.1f", percentile(v, q));
    return std::string(buf);
  };
  const std::vector<double>& f = pacing_.frameMs;
  std::printf(
      "{\"benchmark\": \"viewer\", \"device\": \"%s\", \"scene\": \"%s\", \"mode\": \"%s\", "
      "\"width\": %u, \"height\": %u, \"restarts\": %u, \"units_on_screen\": %u, "
      "\"frames_while_rendering\": %zu, \"ui_fps_while_rendering\": %.2f, "
      "\"frame_ms_p50\": %s, \"frame_ms_p95\": %s, \"frame_ms_max\": %s, "
      "\"camera_moves\": %zu, \"move_to_image_ms_p50\": %s, \"move_to_image_ms_max\": %s, "
      "\"complete_images\": %zu, \"move_to_complete_image_ms_p50\": %s, "
      "\"move_to_complete_image_ms_max\": %s, \"heap_trim_ms_max\": %.1f}\n",
      ctx_.caps().deviceName.c_str(), config_.scenePath.c_str(), mode_.c_str(), renderWidth_,
      renderHeight_, restarts_, shownUnits_, f.size(),
      pacing_.renderingS > 0 ? double(f.size()) / pacing_.renderingS : 0.0, pct(f, 0.5).c_str(),
      pct(f, 0.95).c_str(), pct(f, 1.0).c_str(), pacing_.moveToImageMs.size(),
      pct(pacing_.moveToImageMs, 0.5).c_str(), pct(pacing_.moveToImageMs, 1.0).c_str(),
      pacing_.moveToCompleteMs.size(), pct(pacing_.moveToCompleteMs, 0.5).c_str(),
      pct(pacing_.moveToCompleteMs, 1.0).c_str(), heapTrimMsMax_);
  std::fflush(stdout);
}

int Viewer::run() {
  Clock::time_point last = Clock::now();
  bool lastRendering = false;
  double fpsWindowStart = 0.0;
  int fpsFrames = 0;
  while (!quit_ && !window_.shouldClose()) {
    // Idle (paused or done, no script waiting on time): sleep until input, at most 50 ms, so a
    // finished render does not spin the CPU it shares with everything else.
    if (driver_ && !rendering() && !restartPending_ && scriptNext_ >= script_.size())
      glfwWaitEventsTimeout(0.05);
    else
      glfwPollEvents();
    // The frame period just ended counts towards pacing if the render was refining in it.
    const double dt = secondsSince(last);
    last = Clock::now();
    if (lastRendering) {
      pacing_.frameMs.push_back(1000.0 * dt);
      pacing_.renderingS += dt;
    }
    while (!keys_.empty()) {
      auto [key, mods] = keys_.front();
      keys_.pop_front();
      if (!ImGui::GetIO().WantCaptureKeyboard) onKey(key, mods);
    }
    pollMouseAndFly(dt);
    runScript();
    if (quit_) break;
    handleResize();
    stepRender();
    lastRendering = rendering();
    refreshImage();
    if (secondsSince(lastHeapTrim_) >= kHeapTrimIntervalS) {
      const Clock::time_point t = Clock::now();
      malloc_trim(0);
      lastHeapTrim_ = Clock::now();
      heapTrimMsMax_ = std::max(heapTrimMsMax_, 1000.0 * secondsSince(t));
    }

    uint8_t* pixels = presenter_.beginFrame();
    if (!pixels) {
      int w = 0, h = 0;
      window_.framebufferSize(w, h);
      presenter_.resize({uint32_t(w), uint32_t(h)});
      continue;
    }
    composeFrame(pixels);
    imgui_.newFrame();
    drawPanel();
    const std::string shot = std::exchange(pendingScreenshot_, {});
    if (!presenter_.endFrame([&](VkCommandBuffer cmd) { imgui_.render(cmd); }, shot)) {
      int w = 0, h = 0;
      window_.framebufferSize(w, h);
      presenter_.resize({uint32_t(w), uint32_t(h)});
    }
    // The first image of a restart is on screen once resolved after the restart; the first
    // complete one once a whole unit is.
    if (moveTime_ && !restartPending_ && lastResolve_ > *moveTime_) {
      if (!firstMoveShown_) {
        firstMoveShown_ = true;
        lastMoveToImageMs_ = 1000.0 * secondsSince(*moveTime_);
        if (countLatency_) pacing_.moveToImageMs.push_back(lastMoveToImageMs_);
      }
      if (shownUnits_ >= 1) {
        lastMoveToCompleteMs_ = 1000.0 * secondsSince(*moveTime_);
        if (countLatency_) pacing_.moveToCompleteMs.push_back(lastMoveToCompleteMs_);
        countLatency_ = true;  // not the first image after opening (scene set-up, pipelines)
        moveTime_.reset();
        firstMoveShown_ = false;
      }
    }
    ++fpsFrames;
    const double now = secondsSince(opened_);
    if (now - fpsWindowStart >= 0.5) {
      uiFps_ = fpsFrames / (now - fpsWindowStart);
      fpsWindowStart = now;
      fpsFrames = 0;
    }
  }
  return kExitOk;
}

void Viewer::drawPanel() {
  const VkExtent2D e = presenter_.extent();
  const float x0 = float(std::min<int>(int(renderWidth_), int(e.width) - 1));
  ImGui::SetNextWindowPos(ImVec2(x0, 0.f));
  ImGui::SetNextWindowSize(ImVec2(float(e.width) - x0, float(e.height)));
  ImGui::Begin("osr-vk", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoTitleBar);
  ImGui::PushItemWidth(-110.f);
  ImGui::TextUnformatted(std::filesystem::path(config_.scenePath).filename().string().c_str());
  ImGui::SameLine();
  ImGui::TextDisabled("%ux%u", renderWidth_, renderHeight_);
  ImGui::TextDisabled("%s", ctx_.caps().deviceName.c_str());

  // Progress.
  const render::Progress p = driver_ ? driver_->progress() : render::Progress{};
  ImGui::Separator();
  const char* state = restartPending_                  ? "restarting"
                      : paused_                        ? "paused"
                      : driver_ && driver_->finished() ? "done"
                                                       : "rendering";
  ImGui::Text("%s: %u / %u %s", state, p.units, p.targetUnits, p.unitName);
  const bool done = driver_ && driver_->finished();
  char overlay[64];
  if (done)
    std::snprintf(overlay, sizeof overlay, "all %s done", p.unitName);
  else
    std::snprintf(overlay, sizeof overlay, "%s %u: %.0f%%", p.unitName, p.units + 1,
                  100.0 * p.unitFraction);
  ImGui::ProgressBar(done ? 1.f : float(p.unitFraction), ImVec2(-1, 0), overlay);
  double whole = p.targetUnits ? (p.units + p.unitFraction) / p.targetUnits : 0.0;
  if (driver_ && driver_->settings().timeLimitS > 0.0)
    whole = std::max(whole, p.elapsedS / driver_->settings().timeLimitS);
  if (driver_ && driver_->finished()) whole = 1.0;
  std::snprintf(overlay, sizeof overlay, "render: %.0f%%", 100.0 * std::min(1.0, whole));
  ImGui::ProgressBar(float(std::min(1.0, whole)), ImVec2(-1, 0), overlay);
  if (coarseShown_)
    ImGui::Text("%.1f s, ~%.1f s left; shown: coarse (1/%u size, %u spp)", p.elapsedS, p.remainingS,
                coarse_.factor(), coarse_.samples());
  else
    ImGui::Text("%.1f s, ~%.1f s left; shown: %u", p.elapsedS, p.remainingS, shownUnits_);
  if (ImGui::Button(paused_ ? "Resume (Space)" : "Pause (Space)")) paused_ = !paused_;
  ImGui::SameLine();
  ImGui::TextUnformatted("save");
  ImGui::SameLine();
  if (ImGui::Button("EXR")) save(true, false);
  ImGui::SameLine();
  if (ImGui::Button("PNG")) save(false, true);
  ImGui::SameLine();
  if (ImGui::Button("both (S)")) save(true, true);
  if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());

  // Display.
  ImGui::Separator();
  int layer = int(layer_);
  const char* layers[render::kLayerCount];
  for (int i = 0; i < render::kLayerCount; ++i) layers[i] = render::layerName(render::Layer(i));
  if (ImGui::Combo("layer (1-6)", &layer, layers, render::kLayerCount)) {
    layer_ = render::Layer(layer);
    retonemap();
  }
  if (ImGui::Checkbox("auto", &autoExposure_)) retonemap();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(ImGui::CalcItemWidth() - ImGui::GetCursorPosX() +
                          ImGui::GetStyle().WindowPadding.x);
  if (ImGui::SliderFloat("EV (+/-)", &exposureEv_, -16.f, 16.f, "%.1f")) {
    autoExposure_ = false;
    retonemap();
  }
  int tm = int(toneMap_);
  const char* toneMaps[] = {image::toneMapName(image::ToneMap::Clamp),
                            image::toneMapName(image::ToneMap::Reinhard),
                            image::toneMapName(image::ToneMap::Aces)};
  if (ImGui::Combo("tone map", &tm, toneMaps, 3)) {
    toneMap_ = image::ToneMap(tm);
    retonemap();
  }

  // Integrator and settings: a change restarts at once.
  ImGui::Separator();
  int mode = 0;
  std::vector<const char*> modes;
  for (size_t i = 0; i < config_.modes.size(); ++i) {
    modes.push_back(config_.modes[i].c_str());
    if (config_.modes[i] == mode_) mode = int(i);
  }
  if (ImGui::Combo("integrator", &mode, modes.data(), int(modes.size())) &&
      config_.modes[size_t(mode)] != mode_)
    makeIntegrator(config_.modes[size_t(mode)], renderWidth_, renderHeight_);
  if (ImGui::InputInt(integrator_->unitName(), &targetUnits_, 1, 16)) {
    targetUnits_ = std::clamp(targetUnits_, 1, 1 << 20);
    requestRestart();
  }
  if (ImGui::InputFloat("time limit s", &timeLimit_, 1.f, 10.f, "%.1f")) {
    timeLimit_ = std::max(0.f, timeLimit_);
    requestRestart();
  }
  if (ImGui::InputInt("seed", &seed_)) {
    seed_ = std::max(0, seed_);
    requestRestart();
  }
  if (ImGui::Button("Restart")) requestRestart();

  // Camera.
  ImGui::Separator();
  if (!config_.scene->cameras.empty()) {
    // The closed combo names what it does: the view may have moved off every file camera.
    const std::string preview = std::to_string(config_.scene->cameras.size()) + " in the file";
    if (ImGui::BeginCombo("file camera", preview.c_str())) {
      for (size_t i = 0; i < config_.scene->cameras.size(); ++i) {
        const std::string label = std::to_string(i) + ": " + config_.scene->cameras[i].name;
        if (ImGui::Selectable(label.c_str(), false)) {
          camera_.set(config_.scene->cameras[i]);
          requestRestart();
        }
      }
      ImGui::EndCombo();
    }
  }
  if (ImGui::Button("Reset")) camera_.set(config_.camera), requestRestart();
  ImGui::SameLine();
  if (ImGui::Button("Frame (F)")) camera_.frame(), requestRestart();

  // Timings: GPU time of each pass per unit, two passes a row.
  ImGui::Separator();
  if (driver_ && ImGui::BeginTable("timings", 4, ImGuiTableFlags_SizingStretchProp)) {
    const render::RenderStats& st = driver_->stats();
    const double units = std::max(1.0, double(st.units) + p.unitFraction);
    std::vector<vk::PassTime> rows = st.gpuScopes;
    rows.push_back({"total", st.gpuTotalMs()});
    for (const vk::PassTime& t : rows) {
      ImGui::TableNextColumn();
      ImGui::TextDisabled("%s", t.name.c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%.1f ms", t.ms / units);
    }
    ImGui::EndTable();
  }
  ImGui::TextDisabled("GPU ms per %s", p.unitName == std::string("spp") ? "sample" : "pass");
  ImGui::Text("UI %.1f fps; move->image %.0f ms (full %.0f)", uiFps_, lastMoveToImageMs_,
              lastMoveToCompleteMs_);
  if (ImGui::CollapsingHeader("keys")) ImGui::TextUnformatted(kViewerHelp);
  ImGui::PopItemWidth();
  ImGui::End();
}

}  // namespace

int runViewer(const vk::Context& ctx, const ViewerConfig& config) {
  // A fixed mmap threshold: glibc otherwise raises it (up to 32 MiB) after the first large
  // block is freed, and from then on the viewer's large temporaries (film downloads, layer
  // copies, screenshots) come from the main heap between long-lived small blocks, where freed
  // space is kept. A 20-minute soak grew resident memory 35 % that way while the memory in use
  // stayed at 45 MiB (malloc_stats: 300 MiB held by the heap; docs/benchmarks.md, "soak").
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  // A bad script is bad input: refused before the window opens.
  std::vector<ScriptCommand> script;
  if (!config.scriptPath.empty()) script = readViewerScript(config.scriptPath, config.modes);
  Viewer viewer(ctx, config, std::move(script));
  return viewer.run();
}

}  // namespace osr::viewer
