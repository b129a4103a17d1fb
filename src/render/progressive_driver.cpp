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

double ProgressiveDriver::budgetElapsed() const {
  if (settings_.budgetStart == std::chrono::steady_clock::time_point{}) return elapsed();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - settings_.budgetStart)
      .count();
}

void ProgressiveDriver::restart(const scene::Camera& camera, uint32_t seed) {
  integrator_.restart(camera, seed);
  done_ = 0;
  batch_ = 1;
  secondsPerUnit_ = 0.0;
  secondsPerCost_ = 0.0;
  slice_ = slices_ = 0;
  sliceSeconds_ = 0.0;
  abandoned_ = false;
  stats_ = {};
  started_ = true;
  start_ = std::chrono::steady_clock::now();
}

bool ProgressiveDriver::overBudget(double nextSubmissionS) const {
  return settings_.timeLimitS > 0.0 &&
         budgetElapsed() + settings_.reserveS + 0.5 * nextSubmissionS >= settings_.timeLimitS;
}

bool ProgressiveDriver::finished() const {
  if (!started_ || abandoned_) return true;
  if (done_ >= settings_.maxUnits) return true;
  if (slices_ > 0) {  // a unit in slices: stopped part-way only with stopInUnit
    if (!settings_.stopInUnit || slice_ == 0) return false;
    return overBudget(sliceGroup() * sliceSeconds_ / slice_);
  }
  // Stop when one more unit would end further past the budget than we are before it. The
  // first submission always runs: an image needs something in it.
  if (stats_.submissions == 0 || (done_ == 0 && !settings_.stopInUnit)) return false;
  return overBudget(secondsPerCost_ * integrator_.unitCost(done_));
}

uint32_t ProgressiveDriver::nextBatch() const {
  uint32_t n = std::min(batch_, settings_.maxUnits - done_);
  if (settings_.timeLimitS > 0.0 && secondsPerCost_ > 0.0) {
    // Do not plan past the time budget (at least one unit per submission).
    const double left = settings_.timeLimitS - settings_.reserveS - budgetElapsed();
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
  const uint32_t most = std::max(1u, std::min(integrator_.maxSlicesPerUnit(), settings_.maxSlices));
  if (!settings_.sliceUnits || most == 1) return 1;
  // Nothing measured yet: as many slices as allowed, since a whole unit may take minutes
  // (with stopInUnit they are recorded in groups, so many cost little).
  if (unitSeconds <= 0.0) return most;
  if (unitSeconds <= settings_.batchTargetS) return 1;
  return uint32_t(
      std::min<double>(most, std::ceil(unitSeconds / std::max(settings_.batchTargetS, 1e-6))));
}

// The next unit's seconds: by the cost model once a submission is timed (an OSR map pass
// costs more than the pass before it), else the last unit's before a restart (the viewer).
double ProgressiveDriver::predictedUnitSeconds() const {
  if (secondsPerCost_ > 0.0) return secondsPerCost_ * integrator_.unitCost(done_);
  return lastUnitSeconds_;
}

// Slices of the unit in progress for the next submission: one without stopInUnit; with it as
// many as fit batchTargetS at the seconds per slice measured in this unit (one to start).
uint32_t ProgressiveDriver::sliceGroup() const {
  if (!settings_.stopInUnit || slice_ == 0) return 1;
  const double perSlice = sliceSeconds_ / slice_;
  const double fit = settings_.batchTargetS / std::max(perSlice, 1e-9);
  return uint32_t(std::clamp<double>(std::floor(fit), 1.0, double(slices_ - slice_)));
}

void ProgressiveDriver::abandon(StopReason why) {
  integrator_.abandonUnit(done_, slice_, slices_);
  stats_.abandonedFraction = double(slice_) / slices_;
  stats_.stoppedBy = why;
  slices_ = slice_ = 0;
  abandoned_ = true;
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
  if (finished()) {
    if (slices_ > 0 && !abandoned_ && started_ && done_ < settings_.maxUnits)
      abandon(StopReason::Time);
    return false;
  }
  const double t0 = elapsed();
  uint32_t n = 0;  // units completed by this submission
  if (slices_ == 0) {
    n = nextBatch();
    if (n == 1) {
      const uint32_t s = slicesFor(predictedUnitSeconds());
      if (s > 1) slices_ = s, slice_ = 0, sliceSeconds_ = 0.0;
    }
  }
  if (slices_ > 0) {
    const uint32_t group = sliceGroup();
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      timer_.reset(cmd);
      for (uint32_t s = slice_; s < slice_ + group; ++s)
        integrator_.recordSlice(cmd, done_, s, slices_, &timer_);
    });
    addTimes();
    sliceSeconds_ += elapsed() - t0;
    stats_.submissions++;
    stats_.seconds = elapsed();
    slice_ += group;
    if (slice_ < slices_) return true;
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
  if (cancel && cancel->load(std::memory_order_relaxed)) {
    stats_.stoppedBy = StopReason::Cancelled;
    if (slices_ > 0 && settings_.stopInUnit) abandon(StopReason::Cancelled);
  } else if (!abandoned_ && done_ < settings_.maxUnits) {
    stats_.stoppedBy = StopReason::Time;
  }
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
                     ? std::max(0.0, std::min(byUnits, settings_.timeLimitS - settings_.reserveS -
                                                          budgetElapsed()))
                     : byUnits;
  return p;
}

}  // namespace osr::render
