// The progressive driver against a scripted integrator: unit budget, batching bounds, the time
// budget's stop rule, cancellation, step()/restart() and per-scope GPU times. The path tracer
// under the driver is tested in tests/pt/test_path_integrator.cpp.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "common/vk_test.h"
#include "render/progressive_driver.h"

using namespace osr;

namespace {

// Records one film clear per submission inside a "fake_pass" scope and sleeps `unitS` per
// unit on the host, so wall time per unit is known. Remembers every [first, first + count).
class ScriptedIntegrator : public render::Integrator {
 public:
  ScriptedIntegrator(const vk::Context& ctx, double unitS, uint32_t maxPerSubmission)
      : ctx_(ctx), unitS_(unitS), max_(maxPerSubmission), film_(ctx, 4, 4) {}
  const char* name() const override { return "scripted"; }
  const char* unitName() const override { return "units"; }
  uint32_t maxUnitsPerSubmission() const override { return max_; }
  void restart(const scene::Camera&, uint32_t seed) override {
    seed_ = seed;
    ranges.clear();
    ctx_.submitAndWait([&](VkCommandBuffer cmd) { film_.recordClear(cmd); });
  }
  void record(VkCommandBuffer cmd, uint32_t first, uint32_t count, vk::GpuTimer* timer) override {
    ranges.push_back({first, count});
    vk::TimedScope scope(timer, cmd, "fake_pass");
    film_.recordClear(cmd);
    std::this_thread::sleep_for(std::chrono::duration<double>(unitS_ * count));
  }
  const render::Film& film() const override { return film_; }

  std::vector<std::pair<uint32_t, uint32_t>> ranges;

 private:
  const vk::Context& ctx_;
  double unitS_;
  uint32_t max_;
  render::Film film_;
  uint32_t seed_ = 0;
};

void expectContiguous(const std::vector<std::pair<uint32_t, uint32_t>>& ranges, uint32_t total,
                      uint32_t maxPerSubmission) {
  uint32_t next = 0;
  for (auto [first, count] : ranges) {
    EXPECT_EQ(first, next);
    EXPECT_GE(count, 1u);
    EXPECT_LE(count, maxPerSubmission);
    next = first + count;
  }
  EXPECT_EQ(next, total);
}

TEST(ProgressiveDriver, RunsEveryUnitOnceInBoundedSubmissions) {
  auto& ctx = test::context();
  ScriptedIntegrator integ(ctx, 0.0, 5);
  render::ProgressiveDriver driver(ctx, integ, {37, 0.0, 10.0});
  driver.restart({}, 3);
  std::vector<render::Progress> seen;
  const render::RenderStats& stats = driver.run([&](const render::Progress& p) { seen.push_back(p); });
  EXPECT_EQ(stats.units, 37u);
  expectContiguous(integ.ranges, 37, 5);
  // A long target grows the batch to the integrator's cap after the first unit.
  EXPECT_EQ(integ.ranges.front().second, 1u);
  EXPECT_EQ(integ.ranges[1].second, 5u);
  ASSERT_EQ(seen.size(), integ.ranges.size());
  EXPECT_EQ(seen.back().units, 37u);
  EXPECT_EQ(seen.back().targetUnits, 37u);
  EXPECT_STREQ(seen.back().unitName, "units");
  EXPECT_EQ(seen.back().remainingS, 0.0);
  EXPECT_TRUE(driver.finished());
  EXPECT_FALSE(driver.step());
  // Per-scope GPU time is summed over the render under the scope's name.
  ASSERT_EQ(stats.gpuScopes.size(), ctx.caps().timestamps ? 1u : 0u);
  if (ctx.caps().timestamps) {
    EXPECT_EQ(stats.gpuScopes[0].name, "fake_pass");
    EXPECT_GE(stats.gpuMs("fake_pass"), 0.0);
    EXPECT_EQ(stats.gpuMs("fake_pass"), stats.gpuTotalMs());
  }
  EXPECT_EQ(stats.gpuMs("absent"), 0.0);
}

TEST(ProgressiveDriver, TimeBudgetStopsNearTheBudget) {
  auto& ctx = test::context();
  const double unitS = 0.02, budgetS = 0.3;
  ScriptedIntegrator integ(ctx, unitS, 1000);
  render::ProgressiveDriver driver(ctx, integ, {1u << 20, budgetS, 0.05});
  driver.restart({}, 0);
  const render::RenderStats& stats = driver.run();
  // About budget / unit units; the stop rule never starts a unit that ends more than half a
  // unit past the budget, and batches are planned not to overrun it.
  EXPECT_GE(stats.units, 5u);
  EXPECT_LE(stats.units, uint32_t(budgetS / unitS) + 1);
  EXPECT_LT(stats.seconds, budgetS + 0.25);  // host scheduling slack on a loaded machine
  expectContiguous(integ.ranges, stats.units, 1000);
}

// The seconds held back for what follows the loop (the CLI's resolve and write) end it that
// much earlier: a budget of 0.8 s less 0.5 s is about 0.3 s of 20 ms units.
TEST(ProgressiveDriver, TimeBudgetStopsEarlierByWhatIsHeldBack) {
  auto& ctx = test::context();
  const double unitS = 0.02, budgetS = 0.8, heldS = 0.5;
  ScriptedIntegrator integ(ctx, unitS, 1000);
  render::DriverSettings settings{1u << 20, budgetS, 0.05};
  settings.reserveS = heldS;
  render::ProgressiveDriver driver(ctx, integ, settings);
  driver.restart({}, 0);
  const render::RenderStats& stats = driver.run();
  EXPECT_EQ(stats.stoppedBy, render::StopReason::Time);
  EXPECT_GE(stats.units, 5u);
  EXPECT_LE(stats.units, uint32_t((budgetS - heldS) / unitS) + 1);
  EXPECT_LT(stats.seconds, budgetS - heldS + 0.25);  // host scheduling slack on a loaded machine
  expectContiguous(integ.ranges, stats.units, 1000);
}

TEST(ProgressiveDriver, CancelStopsBetweenSubmissions) {
  auto& ctx = test::context();
  ScriptedIntegrator integ(ctx, 0.0, 1);
  render::ProgressiveDriver driver(ctx, integ, {100, 0.0, 0.25});
  driver.restart({}, 0);
  std::atomic<bool> cancel{false};
  driver.run([&](const render::Progress& p) { cancel = p.units >= 3; }, &cancel);
  EXPECT_EQ(driver.stats().units, 3u);
  EXPECT_FALSE(driver.finished());
}

TEST(ProgressiveDriver, StepAndRestartForAViewer) {
  auto& ctx = test::context();
  ScriptedIntegrator integ(ctx, 0.0, 2);
  render::ProgressiveDriver driver(ctx, integ, {4, 0.0, 10.0});
  EXPECT_FALSE(driver.step()) << "no image before restart()";
  driver.restart({}, 1);
  EXPECT_TRUE(driver.step());
  EXPECT_EQ(driver.progress().units, 1u);
  driver.restart({}, 2);  // the camera moved: start over
  EXPECT_EQ(driver.progress().units, 0u);
  EXPECT_EQ(driver.stats().submissions, 0u);
  while (driver.step()) {
  }
  EXPECT_EQ(driver.stats().units, 4u);
  expectContiguous(integ.ranges, 4, 2);
}

// A unit longer than the target, for an integrator that allows slices: each unit's slices in
// order, one per submission, then the next unit; without sliceUnits units stay whole.
class SlicedIntegrator : public ScriptedIntegrator {
 public:
  SlicedIntegrator(const vk::Context& ctx, double unitS)
      : ScriptedIntegrator(ctx, unitS, 1), unitS_(unitS) {}
  uint32_t maxSlicesPerUnit() const override { return 8; }
  void recordSlice(VkCommandBuffer, uint32_t unit, uint32_t slice, uint32_t slices,
                   vk::GpuTimer*) override {
    slicesSeen.push_back({unit, slice, slices});
    std::this_thread::sleep_for(std::chrono::duration<double>(unitS_ / slices));
  }
  struct Slice {
    uint32_t unit, slice, slices;
  };
  std::vector<Slice> slicesSeen;

 private:
  double unitS_;
};

TEST(ProgressiveDriver, LongUnitsAreSlicedForTheViewer) {
  auto& ctx = test::context();
  SlicedIntegrator integ(ctx, 0.08);
  render::ProgressiveDriver driver(ctx, integ, {3, 0.0, 0.02, true});
  driver.restart({}, 0);
  std::vector<render::Progress> seen;
  driver.run([&](const render::Progress& p) { seen.push_back(p); });
  EXPECT_EQ(driver.stats().units, 3u);
  // Unit 0, with no measured time yet, in the integrator's most slices; units 1 and 2 in
  // slices of about the target.
  EXPECT_TRUE(integ.ranges.empty());
  ASSERT_FALSE(integ.slicesSeen.empty());
  uint32_t unit = 0, next = 0;
  for (const auto& s : integ.slicesSeen) {
    if (s.unit == 0)
      EXPECT_EQ(s.slices, 8u);
    else
      EXPECT_GE(s.slices, 3u);  // 0.08 s / 0.02 s, within the integrator's 8
    EXPECT_LE(s.slices, 8u);
    EXPECT_EQ(s.unit, unit);
    EXPECT_EQ(s.slice, next);
    if (++next == s.slices) ++unit, next = 0;
  }
  EXPECT_EQ(unit, 3u);
  EXPECT_EQ(next, 0u);
  EXPECT_EQ(driver.stats().submissions, integ.slicesSeen.size());
  // Between the slices of a unit, progress says how far the unit is.
  EXPECT_EQ(seen[0].units, 0u);
  EXPECT_DOUBLE_EQ(seen[0].unitFraction, 1.0 / 8);
  EXPECT_EQ(seen.back().unitFraction, 0.0);
  // The same integrator without sliceUnits: whole units only.
  SlicedIntegrator whole(ctx, 0.02);
  render::ProgressiveDriver plain(ctx, whole, {3, 0.0, 0.001});
  plain.restart({}, 0);
  plain.run();
  EXPECT_TRUE(whole.slicesSeen.empty());
  EXPECT_EQ(whole.ranges.size(), 3u);
}

// The CLI's setting (stopInUnit): the untimed first unit in the most slices, recorded in
// groups of about the target; progress during it predicts the remaining time from the slices
// done; the time budget stops it part-way and the integrator is told (abandonUnit).
class AbandoningIntegrator : public SlicedIntegrator {
 public:
  using SlicedIntegrator::SlicedIntegrator;
  uint32_t maxSlicesPerUnit() const override { return 64; }
  void abandonUnit(uint32_t unit, uint32_t slicesDone, uint32_t slices) override {
    abandoned.push_back({unit, slicesDone, slices});
  }
  std::vector<Slice> abandoned;
};

TEST(ProgressiveDriver, StopInUnitGroupsSlicesAndStopsPartWay) {
  auto& ctx = test::context();
  AbandoningIntegrator integ(ctx, 0.64);  // 10 ms a slice, more on a loaded machine
  render::DriverSettings settings{4, 0.5, 0.15, true};
  settings.stopInUnit = true;
  render::ProgressiveDriver driver(ctx, integ, settings);
  driver.restart({}, 0);
  std::vector<render::Progress> seen;
  const render::RenderStats& stats =
      driver.run([&](const render::Progress& p) { seen.push_back(p); });
  ASSERT_FALSE(integ.slicesSeen.empty());
  EXPECT_EQ(integ.slicesSeen[0].slices, 64u);
  EXPECT_EQ(stats.units, 0u);
  // Stopped by the budget, within half a submission of it, inside unit 0.
  EXPECT_LT(stats.seconds, 0.5 + 0.15);
  EXPECT_EQ(stats.stoppedBy, render::StopReason::Time);
  ASSERT_EQ(integ.abandoned.size(), 1u);
  EXPECT_EQ(integ.abandoned[0].unit, 0u);
  EXPECT_EQ(integ.abandoned[0].slice, integ.slicesSeen.size());
  EXPECT_DOUBLE_EQ(stats.abandonedFraction, integ.slicesSeen.size() / 64.0);
  // Grouped: after the first (timed) slice, several slices per submission.
  EXPECT_LT(stats.submissions, integ.slicesSeen.size());
  EXPECT_TRUE(driver.finished());
  EXPECT_FALSE(driver.step());
  // Progress after the first slice: 1/64 of the unit, the rest predicted from it.
  ASSERT_GE(seen.size(), 2u);
  EXPECT_DOUBLE_EQ(seen[0].unitFraction, 1.0 / 64);
  EXPECT_GT(seen[0].remainingS, 0.0);
  EXPECT_LE(seen[0].remainingS, 0.5);
}

// A cancel (Ctrl-C) inside a unit abandons it too, and says so in the stats.
TEST(ProgressiveDriver, CancelInsideAUnitAbandonsIt) {
  auto& ctx = test::context();
  AbandoningIntegrator integ(ctx, 0.64);
  render::DriverSettings settings{4, 0.0, 0.05, true};
  settings.stopInUnit = true;
  render::ProgressiveDriver driver(ctx, integ, settings);
  driver.restart({}, 0);
  std::atomic<bool> cancel{false};
  const render::RenderStats& stats =
      driver.run([&](const render::Progress& p) { cancel = p.unitFraction >= 0.25; }, &cancel);
  EXPECT_EQ(stats.stoppedBy, render::StopReason::Cancelled);
  ASSERT_EQ(integ.abandoned.size(), 1u);
  EXPECT_GE(stats.abandonedFraction, 0.25);
  EXPECT_LT(stats.abandonedFraction, 1.0);
}

TEST(ProgressiveDriver, RefusesAZeroUnitBudget) {
  auto& ctx = test::context();
  ScriptedIntegrator integ(ctx, 0.0, 1);
  EXPECT_ANY_THROW(render::ProgressiveDriver(ctx, integ, {0, 0.0, 0.25}));
}

}  // namespace
