#include "viewer/camera_controller.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace osr::viewer {

namespace {
constexpr glm::vec3 kUp{0.f, 1.f, 0.f};
// Closest approach of the view direction to world up (sin of ~2.6 degrees): lookAt degenerates
// at the poles.
constexpr float kMaxUpDot = 0.999f;
}  // namespace

CameraController::CameraController(const scene::Camera& start, glm::vec3 boundsMin,
                                   glm::vec3 boundsMax)
    : centre_(0.5f * (boundsMin + boundsMax)),
      radius_(std::max(1e-3f, 0.5f * glm::length(boundsMax - boundsMin))) {
  set(start);
}

void CameraController::set(const scene::Camera& camera) {
  camera_ = camera;
  const glm::vec3 eye = glm::vec3(camera.worldFromCamera[3]);
  const glm::vec3 forward = -glm::normalize(glm::vec3(camera.worldFromCamera[2]));
  const float along = std::max(0.1f * radius_, glm::dot(centre_ - eye, forward));
  eye_ = eye;
  target_ = eye + along * forward;
}

void CameraController::update(glm::vec3 eye, glm::vec3 target) {
  glm::vec3 dir = glm::normalize(target - eye);
  if (std::abs(glm::dot(dir, kUp)) > kMaxUpDot) return;  // refuse a degenerate view
  eye_ = eye;
  target_ = target;
  // lookAt gives cameraFromWorld with the camera looking down -Z and +Y up.
  camera_.worldFromCamera = glm::inverse(glm::lookAt(eye_, target_, kUp));
}

void CameraController::orbit(float yawDeg, float pitchDeg) {
  glm::vec3 offset = eye_ - target_;
  const glm::mat4 yaw = glm::rotate(glm::mat4(1.f), glm::radians(-yawDeg), kUp);
  offset = glm::vec3(yaw * glm::vec4(offset, 0.f));
  const glm::vec3 right = glm::normalize(glm::cross(-offset, kUp));
  const glm::mat4 pitch = glm::rotate(glm::mat4(1.f), glm::radians(-pitchDeg), right);
  const glm::vec3 pitched = glm::vec3(pitch * glm::vec4(offset, 0.f));
  if (std::abs(glm::dot(glm::normalize(pitched), kUp)) < kMaxUpDot) offset = pitched;
  update(target_ + offset, target_);
}

void CameraController::pan(float right, float up) {
  const float height = 2.f * glm::length(target_ - eye_) * std::tan(0.5f * camera_.yfov);
  const glm::vec3 r = glm::vec3(camera_.worldFromCamera[0]);
  const glm::vec3 u = glm::vec3(camera_.worldFromCamera[1]);
  const glm::vec3 d = height * (right * r + up * u);
  update(eye_ + d, target_ + d);
}

void CameraController::zoom(float factor) {
  const float dist = std::max(1e-4f * radius_, glm::length(eye_ - target_) * factor);
  update(target_ + dist * glm::normalize(eye_ - target_), target_);
}

void CameraController::fly(float forward, float right, float up) {
  const glm::vec3 f = -glm::vec3(camera_.worldFromCamera[2]);
  const glm::vec3 r = glm::vec3(camera_.worldFromCamera[0]);
  const glm::vec3 u = glm::vec3(camera_.worldFromCamera[1]);
  const glm::vec3 d = radius_ * (forward * f + right * r + up * u);
  update(eye_ + d, target_ + d);
}

void CameraController::look(float yawDeg, float pitchDeg) {
  glm::vec3 offset = target_ - eye_;
  const glm::mat4 yaw = glm::rotate(glm::mat4(1.f), glm::radians(-yawDeg), kUp);
  offset = glm::vec3(yaw * glm::vec4(offset, 0.f));
  const glm::vec3 right = glm::normalize(glm::cross(offset, kUp));
  const glm::mat4 pitch = glm::rotate(glm::mat4(1.f), glm::radians(pitchDeg), right);
  const glm::vec3 pitched = glm::vec3(pitch * glm::vec4(offset, 0.f));
  if (std::abs(glm::dot(glm::normalize(pitched), kUp)) < kMaxUpDot) offset = pitched;
  update(eye_, eye_ + offset);
}

void CameraController::frame() {
  const glm::vec3 back = glm::normalize(eye_ - target_);
  const float aspect = camera_.aspect > 0.f ? camera_.aspect : 1.f;
  const float halfFov =
      0.5f * std::min(camera_.yfov, 2.f * std::atan(aspect * std::tan(0.5f * camera_.yfov)));
  const float dist = radius_ / std::sin(halfFov);
  update(centre_ + dist * back, centre_);
}

}  // namespace osr::viewer
