// The progressive driver: runs an Integrator (render/integrator.h) one submission at a time
// until a stop rule holds, and owns what every front end shares: the unit and time budgets,
// batching (units per submission sized from the measured seconds per unit), progress,
// cancellation and per-pass GPU timings. The CLI calls run(); a viewer calls step() once per
// frame and restart() when the camera moves. The same seed gives the same image: batching
// changes how units are grouped into submissions, never which units are computed. With
// sliceUnits, a unit longer than the batch target is split into slices
// (Integrator::maxSlicesPerUnit), so no submission is much longer than the target where the
// integrator allows it.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "render/integrator.h"
#include "vk/context.h"
#include "vk/timer.h"

namespace osr::render {

struct DriverSettings {
  uint32_t maxUnits = 64;      // stop after this many units (>= 1)
  double timeLimitS = 0.0;     // 0: no limit; otherwise stop starting submissions past it
  double batchTargetS = 0.25;  // aim for submissions this long (progress, time limit, viewer)
  // Split a unit longer than batchTargetS into slices (Integrator::maxSlicesPerUnit): the
  // viewer's submissions must stay short while the window redraws, and the CLI prints progress
  // during a unit that takes minutes. Off: whole units only (tests that count submissions).
  bool sliceUnits = false;
  // With sliceUnits, the CLI's stop rules: --time and Ctrl-C stop within about one submission,
  // even during an OSR pass that takes minutes. A unit in slices may be left unfinished (when
  // the time budget runs out, or run() is cancelled; Integrator::abandonUnit says what the
  // film keeps), and a unit's slices are recorded in groups sized to batchTargetS from the
  // slices timed so far, so the untimed first unit can use the integrator's most slices at
  // little cost. Off (the viewer): one slice per submission, and a unit always finishes.
  bool stopInUnit = false;
  // With sliceUnits, at most this many slices a unit (and the integrator's most): the viewer
  // shows one slice a frame; the CLI, which groups them, allows more for a large image.
  uint32_t maxSlices = 256;
  // Where the clock of timeLimitS starts; unset (the epoch): at restart(). The CLI counts
  // --time from its own start, set-up included.
  std::chrono::steady_clock::time_point budgetStart{};
  // Seconds at the end of timeLimitS held back for what the front end does after the render
  // loop (the CLI resolves the film and writes the image): the loop stops this much earlier.
  double reserveS = 0.0;
};

struct Progress {
  uint32_t units = 0;         // complete units
  double unitFraction = 0.0;  // of the unit in progress, in slices (0 between units)
  uint32_t targetUnits = 0;
  const char* unitName = "";  // Integrator::unitName()
  double elapsedS = 0.0;
  double remainingS = 0.0;  // estimate (from the slices done while no unit has ended yet)
};

// Why a render ended.
enum class StopReason { Units, Time, Cancelled };

struct RenderStats {
  uint32_t units = 0;
  uint32_t submissions = 0;
  double seconds = 0.0;  // wall time since restart (excludes setup and resolve)
  // With stopInUnit: the share of the unit after the last complete one that was recorded when
  // the render stopped part-way through it (0: it stopped between units), and why it stopped.
  double abandonedFraction = 0.0;
  StopReason stoppedBy = StopReason::Units;
  // GPU time of each named timer scope, summed over the render, in first-recorded order
  // (empty where the device has no timestamps).
  std::vector<vk::PassTime> gpuScopes;
  double gpuMs(const std::string& scope) const;  // 0 for a scope never recorded
  double gpuTotalMs() const;
};

class ProgressiveDriver {
 public:
  // `integrator` and `ctx` must outlive the driver. Call restart() before the first step().
  ProgressiveDriver(const vk::Context& ctx, Integrator& integrator, const DriverSettings& settings);

  // Starts a new image (Integrator::restart) and resets units, clock and stats.
  void restart(const scene::Camera& camera, uint32_t seed);
  // Whether a stop rule holds: every unit done, or the time budget used up (one more unit, or
  // with stopInUnit one more submission, would end further past the budget than we are
  // before it).
  bool finished() const;
  // Records, submits and waits for one submission unless finished(); returns whether it did.
  bool step();
  // step() until finished() or *cancel (checked between submissions) becomes true; onProgress
  // (optional) after each submission. With stopInUnit a unit in slices is then abandoned
  // (Integrator::abandonUnit); without, it is finished first. Returns the stats.
  const RenderStats& run(const std::function<void(const Progress&)>& onProgress = {},
                         const std::atomic<bool>* cancel = nullptr);

  Progress progress() const;
  const RenderStats& stats() const { return stats_; }
  const DriverSettings& settings() const { return settings_; }
  Integrator& integrator() const { return integrator_; }

 private:
  double elapsed() const;
  double budgetElapsed() const;  // seconds on the clock of timeLimitS
  uint32_t nextBatch() const;
  uint32_t slicesFor(double unitSeconds) const;
  double predictedUnitSeconds() const;
  uint32_t sliceGroup() const;
  bool overBudget(double nextSubmissionS) const;
  void abandon(StopReason why);
  void addTimes();

  const vk::Context& ctx_;
  Integrator& integrator_;
  DriverSettings settings_;
  vk::GpuTimer timer_;
  std::chrono::steady_clock::time_point start_;
  uint32_t done_ = 0;
  uint32_t batch_ = 1;
  double secondsPerUnit_ = 0.0;
  double secondsPerCost_ = 0.0;  // of Integrator::unitCost, from the last submission
  bool started_ = false;
  // The unit being recorded in slices: slice_ of slices_ done (slices_ 0 between units).
  uint32_t slice_ = 0, slices_ = 0;
  double sliceSeconds_ = 0.0;  // wall time of the current unit's slices so far
  bool abandoned_ = false;     // stopInUnit: the render stopped inside a unit
  // Seconds of the last complete unit, kept across restart(): the same integrator after a
  // camera move costs about the same, so its first unit gets fitting slices (the viewer).
  double lastUnitSeconds_ = 0.0;
  RenderStats stats_;
};

}  // namespace osr::render
