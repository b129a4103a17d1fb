// The progressive schedule of OSR's grid. Map passes trace new maps at spacing r, refining
// from gridStart towards gridMin by a factor sqrt(2) per map pass (each about doubles the
// maps), then go on at gridMin with fresh jitter. Between map passes, passes keep the last
// maps and add direct and residual samples. A pass traces maps only while the maps' share of
// the work so far stays under mapShare, by a cost model in path units (one map texel path or
// one per-pixel path each count 1), so the maps never starve the residual that makes the
// image converge, on any image size; after kMapShareFullPasses passes the bound falls as
// 1 / sqrt(k). A pass's weight is the density of the maps it uses relative to gridMin,
// (gridMin / r)^2: later, denser passes count more than coarse ones.
// Deterministic: pass(k) depends only on k and the constructor's arguments.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace osr::oneshot {

struct GridPass {
  bool traceMaps = false;  // new maps this pass (else the last map pass's are kept)
  uint32_t radius = 0;     // spacing of the maps used this pass
  uint32_t mapPass = 0;    // index of the map pass whose maps are used
  float weight = 1.0f;     // w_k
};

class GridSchedule {
 public:
  // Passes during which map passes may take the whole mapShare; after k passes the bound is
  // mapShare x sqrt(kMapShareFullPasses / k).
  static constexpr double kMapShareFullPasses = 24.0;
  // width x height image; pixelCost: path units of one pass's per-pixel work (direct,
  // residual, G-buffer) per pixel; texelPaths: paths per map texel.
  GridSchedule(uint32_t width, uint32_t height, uint32_t gridStart, uint32_t gridMin,
               double mapShare, double pixelCost, uint32_t texelPaths);
  GridPass pass(uint32_t k);
  // Spacing of map pass m, and the most maps any pass traces.
  uint32_t radiusOfMapPass(uint32_t m) const;
  uint32_t maxMaps() const;
  uint32_t mapsOfRadius(uint32_t r) const;
  glm::uvec2 cellsOfRadius(uint32_t r) const;  // grid cells across and down
  // Path units of the maps pass p traces (0 when it keeps the previous maps).
  double mapWork(const GridPass& p) const;

 private:
  uint32_t width_, height_, start_, min_;
  double mapShare_, pixelCost_, texelPaths_;
  std::vector<GridPass> passes_;
  double mapCost_ = 0.0, totalCost_ = 0.0;
};

}  // namespace osr::oneshot
