// Camera rays from a CameraFrame (shared/camera.h): pinhole, looking down the camera's -Z.
#ifndef OSR_LIB_CAMERA_GLSL
#define OSR_LIB_CAMERA_GLSL
#include "shared/camera.h"

// Ray through pixel (x, y) at sub-pixel offset `jitter` in [0, 1)^2; row 0 is the top.
void cameraRay(CameraFrame f, uint x, uint y, vec2 jitter, out vec3 origin, out vec3 dir) {
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
