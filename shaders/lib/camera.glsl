// Camera rays from a CameraFrame (shared/camera.h): pinhole, looking down the camera's -Z.
#ifndef OSR_LIB_CAMERA_GLSL
#define OSR_LIB_CAMERA_GLSL
#include "shared/camera.h"
#include "shared/pixel_filter.h"

// Index of film pixel `pixel` (row-major in the film) in the whole image: what pixel random
// streams are keyed on, so that they do not depend on the film's window.
uint imagePixelIndex(CameraFrame f, uint pixel) {
  return (pixel / f.width + f.originY) * f.imageWidth + pixel % f.width + f.originX;
}

// Ray through film pixel (x, y) for the pixel-filter sample drawn from `u` in [0, 1)^2 (it may
// land in a neighbouring pixel); row 0 is the top. The default filter (CameraFrame::pixelFilter;
// the other is a 1 px box) is Cycles' Blackman-Harris, sampled by importance
// (shared/pixel_filter.h): a box differs from it by up to 0.3 in radiance beside the cornell
// lamp's edges, which costs more relMSE there than 256 samples of noise.
void cameraRay(CameraFrame f, uint x, uint y, vec2 u, out vec3 origin, out vec3 dir) {
  vec2 jitter = f.pixelFilter == kPixelFilterBox
                    ? u
                    : 0.5 + vec2(blackmanHarrisOffset(u.x), blackmanHarrisOffset(u.y));
  vec2 ndc = vec2((float(x + f.originX) + jitter.x) / float(f.imageWidth) * 2.0 - 1.0,
                  1.0 - (float(y + f.originY) + jitter.y) / float(f.imageHeight) * 2.0);
  vec3 local = vec3(ndc.x * f.tanHalfFovY * f.aspect, ndc.y * f.tanHalfFovY, -1.0);
  origin = f.cameraOrigin.xyz;
  dir = normalize(local.x * f.cameraRight.xyz + local.y * f.cameraUp.xyz +
                  local.z * f.cameraBack.xyz);
}

// Where world point p lies on the film, in pixels (pixel (x, y) covers [x, x + 1) x [y, y + 1));
// the inverse of cameraRay's pixel mapping. Points behind the camera return false.
bool cameraProject(CameraFrame f, vec3 p, out vec2 pixel) {
  vec3 d = p - f.cameraOrigin.xyz;
  float z = -dot(d, f.cameraBack.xyz);
  pixel = vec2(0.0);
  if (z <= 0.0) return false;
  vec2 ndc = vec2(dot(d, f.cameraRight.xyz) / (z * f.tanHalfFovY * f.aspect),
                  dot(d, f.cameraUp.xyz) / (z * f.tanHalfFovY));
  pixel = vec2((ndc.x + 1.0) * 0.5 * float(f.imageWidth) - float(f.originX),
               (1.0 - ndc.y) * 0.5 * float(f.imageHeight) - float(f.originY));
  return true;
}

// Distance of `p` along the camera's view axis (the depth AOV).
float cameraDepth(CameraFrame f, vec3 p) {
  return dot(p - f.cameraOrigin.xyz, -f.cameraBack.xyz);
}

#endif
