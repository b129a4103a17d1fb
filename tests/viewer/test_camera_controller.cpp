// The viewer's camera moves against geometry: orbit keeps the distance to the target, pan
// keeps the view direction, zoom scales the distance, frame() fits the bounding sphere, and
// the camera stays a rigid frame looking at the target.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "viewer/camera_controller.h"

using namespace osr;

namespace {
scene::Camera lookingAt(glm::vec3 eye, glm::vec3 target) {
  scene::Camera c;
  c.worldFromCamera = glm::inverse(glm::lookAt(eye, target, glm::vec3(0, 1, 0)));
  c.yfov = 0.8f;
  c.aspect = 1.f;
  return c;
}
glm::vec3 eyeOf(const scene::Camera& c) {
  return glm::vec3(c.worldFromCamera[3]);
}
glm::vec3 forwardOf(const scene::Camera& c) {
  return -glm::vec3(c.worldFromCamera[2]);
}
void expectRigid(const scene::Camera& c) {
  const glm::mat3 r(c.worldFromCamera);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(glm::length(r[i]), 1.f, 1e-4f);
    for (int j = i + 1; j < 3; ++j) EXPECT_NEAR(glm::dot(r[i], r[j]), 0.f, 1e-4f);
  }
  EXPECT_NEAR(glm::determinant(r), 1.f, 1e-4f);
}
}  // namespace

TEST(CameraController, OrbitPanZoomFrame) {
  // Scene bounds: a unit cube at the origin (radius sqrt(3)); camera 5 units out on +Z.
  viewer::CameraController cc(lookingAt({0, 0, 5}, {0, 0, 0}), glm::vec3(-1), glm::vec3(1));
  EXPECT_NEAR(cc.sceneRadius(), std::sqrt(3.f), 1e-5f);
  cc.orbit(90.f, 0.f);
  expectRigid(cc.camera());
  EXPECT_NEAR(glm::length(eyeOf(cc.camera())), 5.f, 1e-4f);
  EXPECT_NEAR(std::abs(eyeOf(cc.camera()).x), 5.f, 1e-3f) << "a quarter turn about +Y";
  EXPECT_NEAR(glm::dot(forwardOf(cc.camera()), -glm::normalize(eyeOf(cc.camera()))), 1.f, 1e-5f);
  cc.orbit(0.f, 30.f);
  EXPECT_NEAR(glm::length(eyeOf(cc.camera())), 5.f, 1e-4f);
  EXPECT_NEAR(std::abs(eyeOf(cc.camera()).y), 5.f * std::sin(glm::radians(30.f)), 1e-3f);
  // Pitch stops short of the pole instead of flipping.
  for (int i = 0; i < 10; ++i) cc.orbit(0.f, 30.f);
  expectRigid(cc.camera());
  EXPECT_LT(std::abs(forwardOf(cc.camera()).y), 0.9991f);

  viewer::CameraController p(lookingAt({0, 0, 5}, {0, 0, 0}), glm::vec3(-1), glm::vec3(1));
  const glm::vec3 before = forwardOf(p.camera());
  p.pan(0.5f, 0.f);  // half the view height at the target, to the right
  EXPECT_NEAR(glm::dot(forwardOf(p.camera()), before), 1.f, 1e-6f);
  EXPECT_NEAR(eyeOf(p.camera()).x, 0.5f * 2.f * 5.f * std::tan(0.4f), 1e-4f);
  p.zoom(0.5f);
  EXPECT_NEAR(eyeOf(p.camera()).z, 2.5f, 1e-4f);
  p.fly(1.f, 0.f, 0.f);  // one scene radius forward
  EXPECT_NEAR(eyeOf(p.camera()).z, 2.5f - std::sqrt(3.f), 1e-4f);

  viewer::CameraController f(lookingAt({0, 0, 50}, {0, 0, 0}), glm::vec3(-1), glm::vec3(1));
  f.frame();
  EXPECT_NEAR(glm::length(eyeOf(f.camera())), std::sqrt(3.f) / std::sin(0.4f), 1e-3f);
}
