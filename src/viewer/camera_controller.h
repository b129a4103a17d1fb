// Interactive camera over scene::Camera: orbit about a target, pan, zoom (dolly towards the
// target), fly (move eye and target together), frame the scene bounds, and the file's cameras.
// World up is +Y (glTF); the camera looks down its -Z axis with +Y up, as scene::Camera does.
#pragma once
#include <glm/glm.hpp>

#include "scene/scene.h"

namespace osr::viewer {

class CameraController {
 public:
  // `bounds*`: the scene's bounds (frame() and the fly speed scale with them).
  CameraController(const scene::Camera& start, glm::vec3 boundsMin, glm::vec3 boundsMax);

  // Starts from `camera`: the orbit target is the point on its view axis nearest the scene
  // centre (at least a tenth of the scene radius ahead).
  void set(const scene::Camera& camera);
  // Rotates about the target: yaw about world up, pitch about the camera's right axis
  // (degrees; pitch stops short of the poles).
  void orbit(float yawDeg, float pitchDeg);
  // Moves eye and target in the image plane by a fraction of the view height at the target.
  void pan(float right, float up);
  // Multiplies the distance to the target by `factor` (> 0).
  void zoom(float factor);
  // Moves eye and target along the camera's axes, in scene radii.
  void fly(float forward, float right, float up);
  // Turns the view in place (the target moves; degrees).
  void look(float yawDeg, float pitchDeg);
  // Keeps the view direction and moves back until the scene's bounding sphere fits.
  void frame();

  const scene::Camera& camera() const { return camera_; }
  float sceneRadius() const { return radius_; }

 private:
  void update(glm::vec3 eye, glm::vec3 target);
  scene::Camera camera_;
  glm::vec3 eye_{0.f}, target_{0.f}, centre_{0.f};
  float radius_ = 1.f;
};

}  // namespace osr::viewer
