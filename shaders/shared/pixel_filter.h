// Importance sampling of the default pixel filter (lib/camera.glsl): Cycles' Blackman-Harris at
// Cycles' "width 1 px", which Cycles doubles for this window (intern/cycles/scene/film.cpp), so
// it reaches 1 px either side of the pixel centre; the scenes/ references were rendered with it.
// Sampled separably in x and y as Cycles does, so every sample keeps weight 1. One text for the
// device and the host (tests/render/test_pixel_filter.cpp checks it against the exact inverse).
//
// The window over t in [0, 1] (the offset is 2t - 1 pixels) has the CDF
//   C(t) = (a0 t - a1 / k sin(kt) + a2 / 2k sin(2kt) - a3 / 3k sin(3kt)) / a0,   k = 2 pi,
// symmetric about t = 0.5. u in [0, 0.5] is inverted from a first guess, a polynomial in the
// cube root of u (tools/fit_pixel_filter.py; the window's flat tails make the cube root nearly
// linear in t), within about 0.005 of the exact t, then two Newton steps with sin and cos of 2kt
// and 3kt from those of kt, kept within 0.006 of the guess: at the window's edges the density is
// 1.7e-4, where a device's sine (Vulkan allows an error of 2^-11) could otherwise throw a step
// far off. On the host the sample's CDF is then u to float rounding (2.4e-7), for a power, two
// sines and two cosines, where 10 bisection-guarded Newton steps over the whole window took 30
// sines and 30 cosines and missed by up to 0.18 in CDF for a few u in a million. (A table of
// the inverse instead of the polynomial was slower: on lavapipe a constant array read at a
// per-lane index is copied to scratch memory; docs/pathtracer.md, "Benchmark".)
#ifndef OSR_SHARED_PIXEL_FILTER_H
#define OSR_SHARED_PIXEL_FILTER_H
#include "shared/types.h"

#ifdef __cplusplus
#include <cmath>
#define OSR_FILTER_FN inline
namespace osr::gpu::camera {
using glm::clamp;
using glm::max;
using glm::min;
using std::cos;
using std::pow;
using std::sin;
}  // namespace osr::gpu::camera
#else
#define OSR_FILTER_FN
#endif

OSR_NAMESPACE_BEGIN(camera)

// The pixel-filter offset, in pixels from the centre ([-1, 1]), of a uniform u in [0, 1).
OSR_FILTER_FN float blackmanHarrisOffset(float u) {
  const float a0 = 0.35875f, a1 = 0.48829f, a2 = 0.14128f, a3 = 0.01168f;
  const float k = 6.28318530718f;
  bool upper = u > 0.5f;
  float v = upper ? 1.0f - u : u;
  float s = pow(2.0f * v, 1.0f / 3.0f);
  float t = -0.00190343721f + s * (0.993100458f + s * (-1.42885724f + s * (1.43135521f + s * -0.497020118f)));
  float lo = max(t - 0.006f, 0.0f), hi = min(t + 0.006f, 0.5f);
  t = clamp(t, lo, hi);
  for (int step = 0; step < 2; ++step) {
    float s1 = sin(k * t), c1 = cos(k * t);
    float s2 = 2.0f * s1 * c1, c2 = c1 * c1 - s1 * s1;
    float s3 = s2 * c1 + c2 * s1, c3 = c2 * c1 - s2 * s1;
    float cdf = (a0 * t - a1 / k * s1 + a2 / (2.0f * k) * s2 - a3 / (3.0f * k) * s3) / a0;
    float pdf = (a0 - a1 * c1 + a2 * c2 - a3 * c3) / a0;
    t = clamp(t - (cdf - v) / max(pdf, 1e-6f), lo, hi);
  }
  t = upper ? 1.0f - t : t;
  return 2.0f * t - 1.0f;
}

OSR_NAMESPACE_END
#endif
