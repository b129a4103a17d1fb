// The viewer's first images after a restart, at a fraction of the resolution: a path tracer on
// a film 1/f the view's width and height traces a few samples, which are denoised as the view
// would be, upsampled bilinearly to the view's size and shown until the full-resolution film
// has a whole unit. At 512 x 512 one full sample takes 1-2.5 s on lavapipe, and without this the
// window showed the new view band by band over black for that long after every camera move;
// a 128 x 128 film's samples cost a sixteenth of that each. Global illumination is what the
// coarse image is for, so it path traces whatever the view's mode is.
#pragma once
#include <cstdint>
#include <memory>

#include "render/denoiser.h"
#include "render/film.h"
#include "render/progressive_driver.h"
#include "viewer/viewer.h"
#include "vk/context.h"

namespace osr::viewer {

class CoarseStart {
 public:
  // The coarse film has at most this many pixels (f is the smallest power of 2 that fits).
  static constexpr uint32_t kMaxPixels = 128 * 128;
  // Coarse samples traced: a quarter of one full sample's work (f^2 / 4), at most 4 (from
  // 4 on the network denoises them, below the filter). Four at 256 x 256 (f = 2) were a full
  // sample's work, and the image 5 s after a move had half the samples it has without them.
  static constexpr uint32_t kMaxSamples = 4;
  // Slices of a coarse sample at most (the viewer records one a frame). A new coarse film's
  // first sample is unmeasured, and the driver gives such a unit its most slices: 256 frames,
  // seconds, for a sample a 512 x 512 view's first whole unit should not wait on.
  static constexpr uint32_t kMaxSlices = 8;

  // `makeIntegrator` must know the mode "path"; `denoise` is what the view applies (inactive:
  // the coarse image is shown raw).
  CoarseStart(const vk::Context& ctx, IntegratorFactory makeIntegrator,
              render::DenoiseSettings denoise, double stepTargetS);

  // Plans coarse images of `camera` for a width x height view (none where the view is no
  // larger than kMaxPixels). Traces nothing yet.
  void restart(const scene::Camera& camera, uint32_t seed, uint32_t width, uint32_t height);
  // No coarse images until the next restart.
  void cancel() { active_ = false; }
  // Coarse work is left: the view's own render waits until it is done.
  bool running() const { return driver_ && active_ && !driver_->finished(); }
  // One submission of coarse samples; returns whether a new complete sample landed.
  bool step();
  // The coarse film, denoised, upsampled to the view's size into `into`.
  void resolveInto(render::FilmLayers& into);
  uint32_t factor() const { return factor_; }
  uint32_t samples() const { return driver_ ? driver_->stats().units : 0; }

 private:
  const vk::Context& ctx_;
  IntegratorFactory makeIntegrator_;
  render::DenoiseSettings denoise_;
  double stepTargetS_;
  bool active_ = false;
  uint32_t factor_ = 1, width_ = 0, height_ = 0;
  std::unique_ptr<render::Integrator> integrator_;
  std::unique_ptr<render::ProgressiveDriver> driver_;
  std::unique_ptr<render::Denoiser> denoiser_;
  render::FilmLayers coarse_;
};

}  // namespace osr::viewer
