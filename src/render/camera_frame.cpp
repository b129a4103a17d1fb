#include "render/camera_frame.h"

#include <cmath>

namespace osr::render {

gpu::camera::CameraFrame makeFrame(const scene::Camera& camera, uint32_t width, uint32_t height,
                                   uint32_t seed, uint32_t pixelFilter) {
  gpu::camera::CameraFrame f{};
  const glm::mat4& m = camera.worldFromCamera;
  f.cameraRight = glm::vec4(glm::normalize(glm::vec3(m[0])), 0.f);
  f.cameraUp = glm::vec4(glm::normalize(glm::vec3(m[1])), 0.f);
  f.cameraBack = glm::vec4(glm::normalize(glm::vec3(m[2])), 0.f);
  f.cameraOrigin = glm::vec4(glm::vec3(m[3]), 1.f);
  f.width = width;
  f.height = height;
  f.seed = seed;
  f.pixelFilter = pixelFilter;
  const scene::Camera::Window& w = camera.window;
  const bool crop = w.imageWidth > 0;
  f.imageWidth = crop ? w.imageWidth : width;
  f.imageHeight = crop ? w.imageHeight : height;
  f.originX = crop ? w.x : 0u;
  f.originY = crop ? w.y : 0u;
  f.tanHalfFovY = std::tan(0.5f * camera.yfov);
  f.aspect = float(f.imageWidth) / float(f.imageHeight);
  return f;
}

}  // namespace osr::render
