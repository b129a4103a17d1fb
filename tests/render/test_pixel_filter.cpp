// The pixel filter's importance sampling (shaders/shared/pixel_filter.h, the same text the
// camera shaders compile) against the exact inverse of the Blackman-Harris window's CDF. The
// sample distribution on the device is tested end to end by
// PathIntegrator.PixelFilterIsCyclesBlackmanHarris (tests/pt/test_path_integrator.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/pixel_filter_cdf.h"
#include "shaders/shared/pixel_filter.h"

using namespace osr::gpu::camera;

namespace {

// The offset whose CDF is u, by bisection in double precision.
double exactOffset(double u) {
  double lo = -1, hi = 1;
  for (int i = 0; i < 100; ++i) {
    double mid = 0.5 * (lo + hi);
    (osr::test::blackmanHarrisCdf(mid) > u ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

// Over a dense grid of u (both halves, the tails included), the offset's CDF is u to float
// rounding, the offset lies in [-1, 1] within 1e-4 px of the exact inverse, and it increases
// with u.
TEST(PixelFilter, OffsetsFollowTheWindow) {
  const int n = 1 << 20;
  double worst = 0, worstOffset = 0, previous = -2;
  for (int j = 0; j < n; ++j) {
    float u = float(j) / float(n);
    float offset = blackmanHarrisOffset(u);
    ASSERT_GE(offset, -1.f) << "u " << u;
    ASSERT_LE(offset, 1.f) << "u " << u;
    ASSERT_GE(offset, previous) << "u " << u;
    previous = offset;
    worst = std::max(worst, std::abs(osr::test::blackmanHarrisCdf(offset) - u));
    if (j % 64 == 0) worstOffset = std::max(worstOffset, std::abs(offset - exactOffset(u)));
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worstOffset, 1e-4);
  EXPECT_NEAR(blackmanHarrisOffset(0.5f), 0.f, 1e-6);
  EXPECT_NEAR(blackmanHarrisOffset(0.f), -1.f, 1e-6);
}
