// The camera of a render as every pass that shoots camera rays sees it (lib/camera.glsl);
// filled on the host by render::makeCameraFrame.
#ifndef OSR_SHARED_CAMERA_H
#define OSR_SHARED_CAMERA_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(camera)

// CameraFrame::pixelFilter (lib/camera.glsl): Blackman-Harris as Cycles' default film filter
// (what the scenes/ references use), or a 1 px box, whose image at size N / k is exactly the
// k x k box average of the image at size N (what tests comparing at a reduced size need).
OSR_CONST(uint, kPixelFilterBlackmanHarris, 0u);
OSR_CONST(uint, kPixelFilterBox, 1u);

struct CameraFrame {
  vec4 cameraRight;  // worldFromCamera columns: +X
  vec4 cameraUp;     // +Y
  vec4 cameraBack;   // +Z (the camera looks down -Z)
  vec4 cameraOrigin;
  uint width;
  uint height;
  uint seed;
  uint pixelFilter;  // kPixelFilter*
  float tanHalfFovY;
  float aspect;  // width / height of the image
  float _pad1;
  float _pad2;
};

OSR_NAMESPACE_END
#endif
