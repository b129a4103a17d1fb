// The exact CDF of the default pixel filter (Cycles' Blackman-Harris at width 1 px, which
// reaches 1 px either side of the pixel centre), in double precision, for the tests that check
// shaders/shared/pixel_filter.h and the renders it drives against it.
#pragma once
#include <algorithm>
#include <cmath>

namespace osr::test {

// The filter's mass at offsets below `offset` pixels from the centre (0 below -1, 1 above 1).
inline double blackmanHarrisCdf(double offset) {
  const double a0 = 0.35875, a1 = 0.48829, a2 = 0.14128, a3 = 0.01168, k = 2 * M_PI;
  double t = std::clamp(0.5 * (offset + 1.0), 0.0, 1.0);
  return (a0 * t - a1 / k * std::sin(k * t) + a2 / (2 * k) * std::sin(2 * k * t) -
          a3 / (3 * k) * std::sin(3 * k * t)) / a0;
}

}  // namespace osr::test
