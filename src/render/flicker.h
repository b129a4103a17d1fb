// Flicker of a rendered sequence (osr-bench animation, docs/animation.md "Temporal quality"):
// the change from one frame to the next on surfaces seen in both, found by reprojecting with
// depth. Each pixel of frame f whose surface point (its depth through its camera) lands on a
// pixel of frame f - 1 that sees the same point is paired with that pixel; the flicker of a
// pair of images is the mean over paired pixels and channels of (a - b)^2 / (n^2 + 0.01),
// relMSE's form with `n` a normalizing image (the converged frame). The pairing comes from
// the converged frames' depth, so every sequence is measured on the same pixels; an
// identical frame pair under an identical camera has flicker 0.
#pragma once
#include <cstdint>
#include <vector>

#include "shaders/shared/camera.h"

namespace osr::render {

// A frame's view and its per-pixel view-axis depth (FilmLayers::depth: 0 where nothing was hit).
struct DepthView {
  gpu::camera::CameraFrame camera;  // render::makeFrame; a whole image, no window
  const std::vector<float>* depth = nullptr;
};

// Pixel `current` of frame f sees what pixel `previous` of frame f - 1 sees.
struct PixelPair {
  uint32_t current, previous;
};

// Pairs of pixels of `current` and `previous` that see the same surface point: `current`
// pixels whose depth is locally smooth (no silhouette, sky or pixel-filter blend of two
// surfaces: 1 / depth, affine in the image on a plane, has a second difference under 2% of
// its value both ways), reprojected to the nearest pixel centre of `previous`, kept where
// that pixel's depth is within 1% of the point's distance along `previous`'s view axis (not
// occluded, not outside the image). Both views must have the same size.
std::vector<PixelPair> reprojectPairs(const DepthView& current, const DepthView& previous);

// Mean over `pairs` and RGB channels of (current - previous)^2 / (norm^2 + 0.01), `norm` the
// normalizing image at the current pixel (interleaved RGB, as current). 0 without pairs.
double flicker(const std::vector<PixelPair>& pairs, const std::vector<float>& current,
               const std::vector<float>& previous, const std::vector<float>& norm);

}  // namespace osr::render
