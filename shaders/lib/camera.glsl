// Camera rays from a CameraFrame (shared/camera.h): pinhole, looking down the camera's -Z.
#ifndef OSR_LIB_CAMERA_GLSL
#define OSR_LIB_CAMERA_GLSL
#include "shared/camera.h"

// The default pixel filter (CameraFrame::pixelFilter; the other is a 1 px box): Cycles' default, Blackman-Harris at Cycles' "width 1 px", which Cycles
// doubles for this window (intern/cycles/scene/film.cpp), so it reaches 1 px either side of
// the pixel centre; the scenes/ references were rendered with it. A box filter differs from it
// by up to 0.3 in radiance beside the cornell lamp's edges, which costs more relMSE there than
// 256 samples of noise. Sampled by importance, separably in x and y as Cycles does, so every
// sample keeps weight 1: this maps a uniform u in [0, 1) to the window's inverse CDF, in
// pixels from the centre, by Newton steps kept inside a shrinking bisection bracket.
float blackmanHarrisOffset(float u) {
  const float a0 = 0.35875, a1 = 0.48829, a2 = 0.14128, a3 = 0.01168;
  const float k = 2.0 * 3.14159265358979;
  float lo = 0.0, hi = 1.0, t = u;
  for (int i = 0; i < 10; ++i) {  // CDF error below 1e-5 after 10 (measured)
    // CDF and density of the window over t in [0, 1] (the offset is 2t - 1 pixels).
    float cdf = (a0 * t - a1 / k * sin(k * t) + a2 / (2.0 * k) * sin(2.0 * k * t) -
                 a3 / (3.0 * k) * sin(3.0 * k * t)) / a0;
    float pdf = (a0 - a1 * cos(k * t) + a2 * cos(2.0 * k * t) - a3 * cos(3.0 * k * t)) / a0;
    if (cdf > u) hi = t; else lo = t;
    float next = t - (cdf - u) / max(pdf, 1e-6);
    t = next >= lo && next <= hi ? next : 0.5 * (lo + hi);
  }
  return 2.0 * t - 1.0;
}

// Ray through pixel (x, y) for the pixel-filter sample drawn from `u` in [0, 1)^2 (it may
// land in a neighbouring pixel); row 0 is the top.
void cameraRay(CameraFrame f, uint x, uint y, vec2 u, out vec3 origin, out vec3 dir) {
  vec2 jitter = f.pixelFilter == kPixelFilterBox
                    ? u
                    : 0.5 + vec2(blackmanHarrisOffset(u.x), blackmanHarrisOffset(u.y));
  vec2 ndc = vec2((float(x) + jitter.x) / float(f.width) * 2.0 - 1.0,
                  1.0 - (float(y) + jitter.y) / float(f.height) * 2.0);
  vec3 local = vec3(ndc.x * f.tanHalfFovY * f.aspect, ndc.y * f.tanHalfFovY, -1.0);
  origin = f.cameraOrigin.xyz;
  dir = normalize(local.x * f.cameraRight.xyz + local.y * f.cameraUp.xyz +
                  local.z * f.cameraBack.xyz);
}

// Distance of `p` along the camera's view axis (the depth AOV).
float cameraDepth(CameraFrame f, vec3 p) {
  return dot(p - f.cameraOrigin.xyz, -f.cameraBack.xyz);
}

#endif
