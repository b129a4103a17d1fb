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
  for (const char* bad : {"2", "-1", "nope"}) {
    try {
      scene::selectCamera(s, bad, 1.0f);
      FAIL() << "camera '" << bad << "' accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(s.path + ": ", 0), 0u) << e.what();
    }
  }
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
