#include "viewer/coarse_start.h"

#include <malloc.h>

#include <algorithm>

namespace osr::viewer {

CoarseStart::CoarseStart(const vk::Context& ctx, IntegratorFactory makeIntegrator,
                         render::DenoiseSettings denoise, double stepTargetS)
    : ctx_(ctx),
      makeIntegrator_(std::move(makeIntegrator)),
      denoise_(std::move(denoise)),
      stepTargetS_(stepTargetS) {}

void CoarseStart::restart(const scene::Camera& camera, uint32_t seed, uint32_t width,
                          uint32_t height) {
  uint32_t f = 1;
  while (uint64_t(width / f) * (height / f) > kMaxPixels) f *= 2;
  active_ = f > 1;
  if (!active_) return;
  const uint32_t w = std::max(1u, width / f), h = std::max(1u, height / f);
  if (!integrator_ || w != integrator_->film().width() || h != integrator_->film().height()) {
    driver_.reset();
    denoiser_.reset();
    integrator_.reset();
    // As the viewer does for its own integrator: the old one's host memory goes back to the
    // system before the new one is made (a resize makes a new coarse film each time).
    malloc_trim(0);
    integrator_ = makeIntegrator_("path", w, h).integrator;
  }
  factor_ = f;
  width_ = width;
  height_ = height;
  render::DriverSettings ds;
  ds.maxUnits = std::clamp(f * f / 4, 1u, kMaxSamples);
  ds.batchTargetS = stepTargetS_;
  ds.sliceUnits = true;
  ds.maxSlices = kMaxSlices;
  if (!driver_) driver_ = std::make_unique<render::ProgressiveDriver>(ctx_, *integrator_, ds);
  driver_->restart(camera, seed);
}

bool CoarseStart::step() {
  if (!running()) return false;
  const uint32_t before = driver_->stats().units;
  driver_->step();
  return driver_->stats().units > before;
}

void CoarseStart::resolveInto(render::FilmLayers& into) {
  integrator_->resolveInto(coarse_);
  if (denoise_.active()) {
    if (!denoiser_)
      denoiser_ = std::make_unique<render::Denoiser>(ctx_, denoise_, uint32_t(coarse_.width),
                                                     uint32_t(coarse_.height));
    denoiser_->apply(coarse_);
  }
  into.width = int(width_);
  into.height = int(height_);
  render::upsampleBilinear(coarse_, into);
}

}  // namespace osr::viewer
