// The camera of a render as every pass that shoots camera rays sees it (lib/camera.glsl);
// filled on the host by render::makeCameraFrame.
#ifndef OSR_SHARED_CAMERA_H
#define OSR_SHARED_CAMERA_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(camera)

struct CameraFrame {
  vec4 cameraRight;  // worldFromCamera columns: +X
  vec4 cameraUp;     // +Y
  vec4 cameraBack;   // +Z (the camera looks down -Z)
  vec4 cameraOrigin;
  uint width;
  uint height;
  uint seed;
  uint _pad0;
  float tanHalfFovY;
  float aspect;  // width / height of the image
  float _pad1;
  float _pad2;
};

OSR_NAMESPACE_END
#endif
