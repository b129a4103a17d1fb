// The camera of the render tests on analytic views (test_flicker, test_temporal_reuse): at
// x = `x` looking down -Z at a wall at distance 4, 90 degrees vertical field of view, for a
// size x size film: one pixel is 8 / size world units on the wall.
#pragma once
#include <cmath>

#include "render/camera_frame.h"

namespace osr::render::test_views {

inline gpu::camera::CameraFrame wallCamera(float x, uint32_t size) {
  scene::Camera cam;
  cam.yfov = float(M_PI) / 2.f;
  cam.worldFromCamera[3] = glm::vec4(x, 0.f, 0.f, 1.f);
  return makeFrame(cam, size, size, 1);
}

}  // namespace osr::render::test_views
