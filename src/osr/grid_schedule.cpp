#include "osr/grid_schedule.h"

#include <algorithm>
#include <cmath>

namespace osr::oneshot {

GridSchedule::GridSchedule(uint32_t width, uint32_t height, uint32_t gridStart, uint32_t gridMin,
                           double mapShare, double pixelCost, uint32_t texelPaths)
    : width_(width),
      height_(height),
      start_(gridStart),
      min_(std::min(gridMin, gridStart)),
      mapShare_(mapShare),
      pixelCost_(pixelCost),
      texelPaths_(texelPaths) {}

uint32_t GridSchedule::radiusOfMapPass(uint32_t m) const {
  double r = double(start_) / std::pow(std::sqrt(2.0), double(m));
  return std::max(min_, uint32_t(std::lround(r)));
}

glm::uvec2 GridSchedule::cellsOfRadius(uint32_t r) const {
  return {(width_ + r - 1) / r, (height_ + r - 1) / r};
}

uint32_t GridSchedule::mapsOfRadius(uint32_t r) const {
  const glm::uvec2 c = cellsOfRadius(r);
  return c.x * c.y;
}

double GridSchedule::mapWork(const GridPass& p) const {
  return p.traceMaps ? double(mapsOfRadius(p.radius)) * 1024.0 * texelPaths_ : 0.0;
}

uint32_t GridSchedule::maxMaps() const {
  return mapsOfRadius(min_);
}

GridPass GridSchedule::pass(uint32_t k) {
  while (passes_.size() <= k) {
    GridPass p;
    const uint32_t mapPasses = passes_.empty() ? 0 : passes_.back().mapPass + 1;
    // The share falls after kMapShareFullPasses passes: by then the residual blend has
    // measured where the maps are wrong and shows the residual there, so later maps buy
    // little and their paths do more as residual paths.
    const double passes = double(passes_.size());
    const double share =
        mapShare_ * std::sqrt(std::min(1.0, kMapShareFullPasses / std::max(passes, 1.0)));
    p.traceMaps = passes_.empty() || mapCost_ <= share * totalCost_;
    p.mapPass = p.traceMaps ? mapPasses : passes_.back().mapPass;
    p.radius = radiusOfMapPass(p.mapPass);
    const double density = double(min_) / double(p.radius);
    p.weight = float(density * density);
    const double pixelWork = pixelCost_ * double(width_) * height_;
    mapCost_ += mapWork(p);
    totalCost_ += mapWork(p) + pixelWork;
    passes_.push_back(p);
  }
  return passes_[k];
}

}  // namespace osr::oneshot
