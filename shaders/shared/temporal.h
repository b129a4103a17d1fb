// Temporal reuse of a shot's film (src/render/temporal_reuse.h, film_temporal.comp), shared by
// GLSL and C++. Each frame's layers are one vec4 per pixel, row-major, row 0 at the top:
//   combined: rgb the film's colour; w: variance of the pixel's luminance estimate
//   direct, indirect: rgb the film's layers; indirect.w (written): the samples behind the
//     pixel's blended estimate, its own and the history's it took
//   albedo: rgb the first-hit albedo; w: the first hit's view-axis depth (0: no hit)
//   normal: xyz the first-hit normal; w: the share of camera rays that saw light directly
// The previous frame's blended layers, in the same form, are the history.
#ifndef OSR_SHARED_TEMPORAL_H
#define OSR_SHARED_TEMPORAL_H
#include "shared/camera.h"
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(temporal)

OSR_CONST(uint, kTemporalTile, 8);  // 8 x 8 pixels per workgroup

OSR_CONST(uint, kBindingCombined, 0);  // the frame's layers, read and written in place
OSR_CONST(uint, kBindingDirect, 1);
OSR_CONST(uint, kBindingIndirect, 2);
OSR_CONST(uint, kBindingAlbedo, 3);
OSR_CONST(uint, kBindingNormal, 4);
OSR_CONST(uint, kBindingHistoryCombined, 5);  // the previous frame's, read only
OSR_CONST(uint, kBindingHistoryDirect, 6);
OSR_CONST(uint, kBindingHistoryIndirect, 7);
OSR_CONST(uint, kBindingHistoryAlbedo, 8);
OSR_CONST(uint, kBindingHistoryNormal, 9);
OSR_CONST(uint, kBindingCameras, 10);  // TemporalCameras
// The frame's combined colour as its film gave it, read only: the neighbourhood the history
// is tested against, which the pass's in-place writes must not change under it.
OSR_CONST(uint, kBindingFrameColour, 11);
OSR_CONST(uint, kTemporalBindingCount, 12);

#ifdef __cplusplus
using camera::CameraFrame;
#endif
struct TemporalCameras {
  CameraFrame current;
  CameraFrame previous;
};

struct TemporalPush {
  uint width;
  uint height;
  float samples;      // the frame's own samples per pixel
  float maxHistory;   // the history counts for at most this many times `samples`
  float rejectSigma;  // history further than this many spreads from the frame's is dropped
  uint _pad0;
  uint _pad1;
  uint _pad2;
};

OSR_NAMESPACE_END
#endif
