#include "osr/grid_schedule.h"

#include <algorithm>
#include <cmath>

namespace osr::oneshot {

namespace {
// Spacing of map pass m: gridStart / sqrt(2)^m, never below gridMin.
uint32_t radiusOfMapPass(uint32_t start, uint32_t min, uint32_t m) {
  double r = double(start) / std::pow(std::sqrt(2.0), double(m));
  return std::max(min, uint32_t(std::lround(r)));
}
}  // namespace

GridSchedule::GridSchedule(uint32_t gridStart, uint32_t gridMin, uint32_t mapPassesAtMin)
    : start_(gridStart), min_(std::min(gridMin, gridStart)), mapPasses_(0) {
  // Map passes until gridMin is reached, then mapPassesAtMin more (at least the first).
  uint32_t m = 0;
  while (radiusOfMapPass(start_, min_, m) > min_) ++m;
  mapPasses_ = m + std::max(1u, mapPassesAtMin);
}

GridPass GridSchedule::pass(uint32_t k) const {
  GridPass p;
  p.traceMaps = k < mapPasses_;
  p.mapPass = std::min(k, mapPasses_ - 1);
  p.radius = radiusOfMapPass(start_, min_, p.mapPass);
  float density = float(min_) / float(p.radius);
  p.weight = density * density;
  return p;
}

}  // namespace osr::oneshot
