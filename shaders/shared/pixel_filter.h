// Importance sampling of the default pixel filter (lib/camera.glsl): Cycles' Blackman-Harris at
// Cycles' "width 1 px", which Cycles doubles for this window (intern/cycles/scene/film.cpp), so
// it reaches 1 px either side of the pixel centre; the scenes/ references were rendered with it.
// Sampled separably in x and y as Cycles does, so every sample keeps weight 1. One text for the
// device and the host (tests/render/test_pixel_filter.cpp checks it against the exact inverse).
//
// The window over t in [0, 1] (the offset is 2t - 1 pixels) has the CDF
//   C(t) = (a0 t - a1 / k sin(kt) + a2 / 2k sin(2kt) - a3 / 3k sin(3kt)) / a0,   k = 2 pi,
// symmetric about t = 0.5. u in [0, 0.5] is inverted from a table spaced evenly in the cube root
// of u (the window's flat tails make that nearly linear in t), linear interpolation between its
// entries, then one Newton step kept inside them, with sin and cos of 2kt and 3kt from those of
// kt. The sample's CDF is then u to float rounding (2.7e-7; t itself may be off by 1e-3 in the
// tails, where the density is 1e-4 and that moves no mass), for a power, a sine and a cosine
// where 10 bisection-guarded Newton steps over the whole window took 30 sines and 30 cosines
// and missed by up to 0.18 in CDF for a few u in a million (pt_trace and osr_gbuffer times did
// not measurably change).
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
inline float sin(float x) { return std::sin(x); }
inline float cos(float x) { return std::cos(x); }
inline float pow(float x, float y) { return std::pow(x, y); }
}  // namespace osr::gpu::camera
#else
#define OSR_FILTER_FN
#endif

OSR_NAMESPACE_BEGIN(camera)

// kBlackmanHarrisInverse[i]: the t in [0, 0.5] with C(t) = 0.5 (i / kBlackmanHarrisSteps)^3,
// from tools/gen_pixel_filter_table.py (rerun it to change kBlackmanHarrisSteps).
OSR_CONST(int, kBlackmanHarrisSteps, 32);
#define OSR_BH_INVERSE_TABLE \
    0.0f, 0.0270731279f, 0.0567725351f, 0.082084333f, 0.104371761f, 0.124438974f, 0.142842148f, \
    0.159968575f, 0.176093959f, 0.191420521f, 0.206101238f, 0.220255277f, 0.233978051f, \
    0.247347934f, 0.260430888f, 0.273283748f, 0.285956631f, 0.298494759f, 0.310939893f, \
    0.323331518f, 0.335707859f, 0.34810682f, 0.360566894f, 0.373128109f, 0.385833083f, \
    0.398728241f, 0.411865321f, 0.425303294f, 0.43911091f, 0.453370199f, 0.468181444f, \
    0.483670496f, 0.5f
#ifdef __cplusplus
inline constexpr float kBlackmanHarrisInverse[kBlackmanHarrisSteps + 1] = {OSR_BH_INVERSE_TABLE};
#else
const float kBlackmanHarrisInverse[kBlackmanHarrisSteps + 1] = float[kBlackmanHarrisSteps + 1](OSR_BH_INVERSE_TABLE);
#endif
#undef OSR_BH_INVERSE_TABLE

// The pixel-filter offset, in pixels from the centre ([-1, 1]), of a uniform u in [0, 1).
OSR_FILTER_FN float blackmanHarrisOffset(float u) {
  const float a0 = 0.35875f, a1 = 0.48829f, a2 = 0.14128f, a3 = 0.01168f;
  const float k = 6.28318530718f;
  bool upper = u > 0.5f;
  float v = upper ? 1.0f - u : u;
  float s = pow(2.0f * v, 1.0f / 3.0f) * float(kBlackmanHarrisSteps);
  int i = min(int(s), kBlackmanHarrisSteps - 1);
  float lo = kBlackmanHarrisInverse[i], hi = kBlackmanHarrisInverse[i + 1];
  float t = lo + (hi - lo) * (s - float(i));
  float s1 = sin(k * t), c1 = cos(k * t);
  float s2 = 2.0f * s1 * c1, c2 = c1 * c1 - s1 * s1;
  float s3 = s2 * c1 + c2 * s1, c3 = c2 * c1 - s2 * s1;
  float cdf = (a0 * t - a1 / k * s1 + a2 / (2.0f * k) * s2 - a3 / (3.0f * k) * s3) / a0;
  float pdf = (a0 - a1 * c1 + a2 * c2 - a3 * c3) / a0;
  t = clamp(t - (cdf - v) / max(pdf, 1e-6f), lo, hi);
  t = upper ? 1.0f - t : t;
  return 2.0f * t - 1.0f;
}

OSR_NAMESPACE_END
#endif
