// The per-render camera constants every integrator's camera rays start from.
#pragma once
#include <cstdint>

#include "scene/scene.h"
#include "shaders/shared/camera.h"

namespace osr::render {

// The frame of `camera` for a width x height film and `seed` (width, height >= 1): the whole
// image, or the window camera.window of a larger one (the caller checks that it fits);
// pixelFilter: gpu::camera::kPixelFilter*.
gpu::camera::CameraFrame makeFrame(const scene::Camera& camera, uint32_t width, uint32_t height,
                                   uint32_t seed,
                                   uint32_t pixelFilter = gpu::camera::kPixelFilterBlackmanHarris);

}  // namespace osr::render
