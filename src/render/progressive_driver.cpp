#include "render/progressive_driver.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace osr::render {

namespace {
// Timer scopes one submission may open: an OSR pass opens 5 per chunk of maps (512 maps), so
// 3840 x 2160 at grid spacing 16 needs about 330 and 7680 x 4320 about 1270; a query pool of
// this size costs 64 KiB.
constexpr uint32_t kMaxScopesPerSubmission = 4096;
}  // namespace

double RenderStats::gpuMs(const std::string& scope) const {
  for (const vk::PassTime& t : gpuScopes)
    if (t.name == scope) return t.ms;
  return 0.0;
}

double RenderStats::gpuTotalMs() const {
  double sum = 0.0;
  for (const vk::PassTime& t : gpuScopes) sum += t.ms;
  return sum;
}

ProgressiveDriver::ProgressiveDriver(const vk::Context& ctx, Integrator& integrator,
                                     const DriverSettings& settings)
    : ctx_(ctx), integrator_(integrator), settings_(settings), timer_(ctx, kMaxScopesPerSubmission) {
  if (settings_.maxUnits == 0) throw InputError("render: the unit budget must be at least 1");
}

double ProgressiveDriver::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressiveDriver::restart(const scene::Camera& camera, uint32_t seed) {
  integrator_.restart(camera, seed);
  done_ = 0;
  batch_ = 1;
  secondsPerUnit_ = 0.0;
  secondsPerCost_ = 0.0;
  slice_ = slices_ = 0;
  sliceSeconds_ = 0.0;
  stats_ = {};
  started_ = true;
  start_ = std::chrono::steady_clock::now();
}

bool ProgressiveDriver::finished() const {
  if (!started_) return true;
  if (done_ >= settings_.maxUnits) return true;
  if (slices_ > 0) return false;  // a unit in slices is finished before any stop rule
  // Stop when one more unit would end further past the budget than we are before it.
  return settings_.timeLimitS > 0.0 && done_ > 0 &&
         elapsed() + 0.5 * secondsPerCost_ * integrator_.unitCost(done_) >= settings_.timeLimitS;
}

uint32_t ProgressiveDriver::nextBatch() const {
  uint32_t n = std::min(batch_, settings_.maxUnits - done_);
  if (settings_.timeLimitS > 0.0 && secondsPerCost_ > 0.0) {
    // Do not plan past the time budget (at least one unit per submission).
    const double left = settings_.timeLimitS - elapsed();
    double planned = 0.0;
    uint32_t fit = 0;
    while (fit < n) {
      planned += secondsPerCost_ * integrator_.unitCost(done_ + fit);
      if (planned > left) break;
      ++fit;
    }
    n = std::max<uint32_t>(1, fit);
  }
  return n;
}

uint32_t ProgressiveDriver::slicesFor(double unitSeconds) const {
  const uint32_t most = std::max(1u, integrator_.maxSlicesPerUnit());
  if (!settings_.sliceUnits || most == 1) return 1;
  // Nothing measured yet: as many slices as allowed (or asked for), since a whole unit may
  // take seconds.
  if (unitSeconds <= 0.0)
    return settings_.firstUnitSlices ? std::clamp(settings_.firstUnitSlices, 1u, most) : most;
  if (unitSeconds <= settings_.batchTargetS) return 1;
  return uint32_t(
      std::min<double>(most, std::ceil(unitSeconds / std::max(settings_.batchTargetS, 1e-6))));
}

void ProgressiveDriver::addTimes() {
  for (const vk::PassTime& t : timer_.results()) {
    auto it = std::find_if(stats_.gpuScopes.begin(), stats_.gpuScopes.end(),
                           [&](const vk::PassTime& s) { return s.name == t.name; });
    if (it == stats_.gpuScopes.end())
      stats_.gpuScopes.push_back(t);
    else
      it->ms += t.ms;
  }
}

bool ProgressiveDriver::step() {
  if (finished()) return false;
  const double t0 = elapsed();
  uint32_t n = 0;  // units completed by this submission
  if (slices_ == 0) {
    n = nextBatch();
    if (n == 1) {
      const uint32_t s = slicesFor(secondsPerUnit_ > 0.0 ? secondsPerUnit_ : lastUnitSeconds_);
      if (s > 1) slices_ = s, slice_ = 0, sliceSeconds_ = 0.0;
    }
  }
  if (slices_ > 0) {
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      timer_.reset(cmd);
      integrator_.recordSlice(cmd, done_, slice_, slices_, &timer_);
    });
    addTimes();
    sliceSeconds_ += elapsed() - t0;
    stats_.submissions++;
    stats_.seconds = elapsed();
    if (++slice_ < slices_) return true;
    slices_ = 0;
    n = 1;
  } else {
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      timer_.reset(cmd);
      integrator_.record(cmd, done_, n, &timer_);
    });
    addTimes();
    sliceSeconds_ = elapsed() - t0;
    stats_.submissions++;
  }
  const double dt = sliceSeconds_;
  double cost = 0.0;
  for (uint32_t k = done_; k < done_ + n; ++k) cost += integrator_.unitCost(k);
  done_ += n;
  secondsPerUnit_ = lastUnitSeconds_ = dt / n;
  secondsPerCost_ = dt / std::max(cost, 1e-12);
  // Grow or shrink the batch towards the target submission length.
  batch_ = std::clamp<uint32_t>(
      uint32_t(settings_.batchTargetS / std::max(secondsPerUnit_, 1e-6)), 1u,
      std::max(1u, integrator_.maxUnitsPerSubmission()));
  stats_.units = done_;
  stats_.seconds = elapsed();
  return true;
}

const RenderStats& ProgressiveDriver::run(const std::function<void(const Progress&)>& onProgress,
                                          const std::atomic<bool>* cancel) {
  while (!(cancel && cancel->load(std::memory_order_relaxed)) && step())
    if (onProgress) onProgress(progress());
  stats_.seconds = elapsed();
  return stats_;
}

Progress ProgressiveDriver::progress() const {
  Progress p;
  p.units = done_;
  p.unitFraction = slices_ > 0 ? double(slice_) / slices_ : 0.0;
  p.targetUnits = settings_.maxUnits;
  p.unitName = integrator_.unitName();
  p.elapsedS = started_ ? elapsed() : 0.0;
  // Before the first unit ends, its slices so far predict its length.
  double perUnit = secondsPerUnit_;
  if (perUnit <= 0.0 && slices_ > 0 && slice_ > 0) perUnit = sliceSeconds_ * slices_ / slice_;
  const double byUnits = (settings_.maxUnits - done_ - p.unitFraction) * perUnit;
  p.remainingS = settings_.timeLimitS > 0.0
                     ? std::max(0.0, std::min(byUnits, settings_.timeLimitS - p.elapsedS))
                     : byUnits;
  return p;
}

}  // namespace osr::render
