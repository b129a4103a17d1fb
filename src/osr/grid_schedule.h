// The progressive schedule of OSR's grid: pass k traces new maps at spacing r_k, refining
// from gridStart towards gridMin by a factor sqrt(2) per pass (each map pass about doubles
// the maps), then mapPassesAtMin more at gridMin with fresh jitter; later passes keep the
// last maps and add residual samples. A pass's weight is its maps' density relative to
// gridMin, (gridMin / r)^2, so later, denser passes count more than the first coarse ones.
#pragma once
#include <cstdint>

namespace osr::oneshot {

struct GridPass {
  bool traceMaps = false;  // new maps this pass (else the previous pass's are kept)
  uint32_t radius = 0;     // spacing of the maps used this pass
  uint32_t mapPass = 0;    // index of the map pass whose maps are used
  float weight = 1.0f;     // w_k
};

class GridSchedule {
 public:
  GridSchedule(uint32_t gridStart, uint32_t gridMin, uint32_t mapPassesAtMin);
  GridPass pass(uint32_t k) const;
  uint32_t mapPassCount() const { return mapPasses_; }

 private:
  uint32_t start_, min_, mapPasses_;
};

}  // namespace osr::oneshot
