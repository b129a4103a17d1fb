// Camera choice: file cameras by index and name (bad selectors are InputErrors naming the
// scene), their rigid transforms, and the default camera framing the bounds.
#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "common/test_paths.h"
#include "scene/scene.h"
#include "scene/scene_test_util.h"

using namespace osr;
using test::expectNear;
using test::hasWarning;

namespace {

std::string data(const std::string& name) {
  return test::dataPath("scene/" + name);
}

}  // namespace

TEST(Camera, CamerasAndSelection) {
  scene::Scene s = scene::loadScene(data("cameras.gltf"));
  ASSERT_EQ(s.cameras.size(), 2u);  // the orthographic one is skipped with a warning
  EXPECT_TRUE(hasWarning(s, "orthographic"));
  EXPECT_EQ(s.cameras[0].name, "wide");
  EXPECT_FLOAT_EQ(s.cameras[0].yfov, 1.2f);
  EXPECT_FLOAT_EQ(s.cameras[0].aspect, 1.5f);
  EXPECT_EQ(s.cameras[1].name, "closeup");  // unnamed camera: its node's name
  EXPECT_FLOAT_EQ(s.cameras[1].aspect, 0.0f);
  // Scale 3 on the node is dropped: rigid transform.
  expectNear(glm::vec3(s.cameras[1].worldFromCamera[0]), {1, 0, 0});
  expectNear(glm::vec3(s.cameras[1].worldFromCamera[3]), {0.5f, 0.5f, 2});
  EXPECT_EQ(scene::selectCamera(s, "", 1.0f).name, "wide");
  EXPECT_EQ(scene::selectCamera(s, "1", 1.0f).name, "closeup");
  EXPECT_EQ(scene::selectCamera(s, "closeup", 1.0f).name, "closeup");
  // Numbers are the file's camera indices, as the loader's warning numbers them: camera 2 is
  // the orthographic one, and the message says which cameras can be used.
  auto message = [&](const char* selector) {
    try {
      scene::selectCamera(s, selector, 1.0f);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("2"), s.path + ": camera 2 is orthographic, which osr-vk cannot render "
                                   "(usable cameras: 0, 1)");
  EXPECT_EQ(message("3"), s.path + ": camera 3 does not exist (the file has 3 camera(s); "
                                   "usable: 0, 1)");
  for (const char* bad : {"2", "-1", "nope"}) {
    try {
      scene::selectCamera(s, bad, 1.0f);
      FAIL() << "camera '" << bad << "' accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(s.path + ": ", 0), 0u) << e.what();
    }
  }
}

// The default camera is a three-quarter view: it looks across the scene from the front-right
// and from above, so that a box shows three faces (a face-on view shows one).
TEST(Camera, DefaultCameraIsAThreeQuarterView) {
  scene::Scene s = scene::loadScene(data("hierarchy.gltf"));
  scene::Camera c = scene::selectCamera(s, "", 1.0f);
  const glm::vec3 forward = -glm::vec3(c.worldFromCamera[2]);  // glTF cameras look down -Z
  const glm::vec3 up = glm::vec3(c.worldFromCamera[1]);
  EXPECT_LT(forward.x, -0.3f) << "looks from +X towards -X";
  EXPECT_LT(forward.z, -0.5f) << "looks from +Z towards -Z";
  EXPECT_LT(forward.y, -0.3f) << "looks down";
  EXPECT_GT(up.y, 0.5f) << "upright";
  EXPECT_NEAR(c.worldFromCamera[0].y, 0.f, 1e-5f) << "no roll: the right axis is horizontal";
  // Its position is where it looks from: the centre minus forward times the distance.
  const glm::vec3 center = 0.5f * (s.boundsMin + s.boundsMax);
  const glm::vec3 eye = glm::vec3(c.worldFromCamera[3]);
  EXPECT_LT(glm::length(glm::normalize(center - eye) - forward), 1e-4f);
}

TEST(Camera, DefaultCameraFramesTheBounds) {
  scene::Scene s = scene::loadScene(data("hierarchy.gltf"));
  ASSERT_TRUE(s.cameras.empty());
  for (float aspect : {0.5f, 1.0f, 2.0f}) {
    scene::Camera c = scene::selectCamera(s, "", aspect);
    EXPECT_FLOAT_EQ(c.aspect, aspect);
    glm::mat4 cameraFromWorld = glm::inverse(c.worldFromCamera);
    float tanY = std::tan(0.5f * c.yfov), tanX = tanY * aspect;
    for (int corner = 0; corner < 8; ++corner) {
      glm::vec3 p((corner & 1) ? s.boundsMax.x : s.boundsMin.x,
                  (corner & 2) ? s.boundsMax.y : s.boundsMin.y,
                  (corner & 4) ? s.boundsMax.z : s.boundsMin.z);
      glm::vec3 q = glm::vec3(cameraFromWorld * glm::vec4(p, 1.0f));
      ASSERT_LT(q.z, 0.0f) << "corner " << corner << " behind the camera";
      EXPECT_LE(std::abs(q.x / -q.z), tanX) << "corner " << corner << " aspect " << aspect;
      EXPECT_LE(std::abs(q.y / -q.z), tanY) << "corner " << corner << " aspect " << aspect;
    }
  }
}
