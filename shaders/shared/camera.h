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

// The film may be a window of a larger image (--crop): film pixel (x, y) is image pixel
// (x + originX, y + originY) of an imageWidth x imageHeight image, and camera rays, pixel
// random streams and pixel footprints are the image's, so a window renders the pixels the
// whole image would (path mode: bit for bit). Without a crop the film is the image.
struct CameraFrame {
  vec4 cameraRight;  // worldFromCamera columns: +X
  vec4 cameraUp;     // +Y
  vec4 cameraBack;   // +Z (the camera looks down -Z)
  vec4 cameraOrigin;
  uint width;   // of the film: the pixels this render computes
  uint height;
  uint seed;
  uint pixelFilter;  // kPixelFilter*
  float tanHalfFovY;
  float aspect;  // imageWidth / imageHeight
  float _pad1;
  float _pad2;
  uint imageWidth;  // of the whole image the film is a window of
  uint imageHeight;
  uint originX;  // the film's top-left pixel in the image
  uint originY;
};

OSR_NAMESPACE_END
#endif
