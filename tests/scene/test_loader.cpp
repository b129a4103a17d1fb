// The glTF loader on the reference scenes and on hand-made files covering each feature, and
// its refusal of bad input (InputError naming the file).
#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "common/vk_test.h"
#include "scene/scene.h"

using namespace osr;
namespace gs = osr::gpu::scene;

namespace {

const gs::Material* findEmissive(const scene::Scene& s, glm::vec3 emission) {
  for (const auto& m : s.materials)
    if (glm::length(m.emission - emission) < 1e-4f) return &m;
  return nullptr;
}

}  // namespace

TEST(Loader, Cornell) {
  scene::Scene s = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  EXPECT_EQ(s.triangles.size(), 86u);
  EXPECT_EQ(s.materials.size(), 4u);  // every primitive has a material: no default added
  // Ceiling light: emissiveFactor (1, 0.78, 0.5) x KHR_materials_emissive_strength 17.
  EXPECT_NE(findEmissive(s, glm::vec3(17.0f, 0.78f * 17.0f, 0.5f * 17.0f)), nullptr);
  ASSERT_FALSE(s.emissive.empty());
  EXPECT_FLOAT_EQ(s.emissive.back().cdf, 1.0f);
  for (size_t i = 1; i < s.emissive.size(); ++i) EXPECT_GE(s.emissive[i].cdf, s.emissive[i - 1].cdf);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_EQ(s.cameras[0].name, "Camera");
  EXPECT_NEAR(s.cameras[0].yfov, 0.6806784f, 1e-6f);
  EXPECT_FLOAT_EQ(s.cameras[0].aspect, 1.0f);
  EXPECT_NEAR(s.cameras[0].worldFromCamera[3].z, 3.9f, 1e-5f);
  EXPECT_NEAR(s.cameras[0].worldFromCamera[3].y, 1.0f, 1e-5f);
  // The box spans about [-1, 1] x [0, 2] x [-1, 1] (walls 5 cm thick).
  EXPECT_NEAR(s.boundsMin.y, -0.05f, 0.03f);
  EXPECT_NEAR(s.boundsMax.y, 2.05f, 0.03f);
  EXPECT_LT(s.boundsMin.x, -0.99f);
  EXPECT_GT(s.boundsMax.x, 0.99f);
  EXPECT_TRUE(s.warnings.empty());
  // Lambertian walls as exported by Blender: specular colour 0, ior 1.45, double-sided.
  EXPECT_EQ(s.materials[0].specularColor, glm::vec3(0.0f));
  EXPECT_NEAR(s.materials[0].ior, 1.45f, 1e-6f);
  EXPECT_TRUE(s.materials[0].flags & gs::kMaterialDoubleSided);
  // Every vertex normal is unit length, every triangle index in range.
  for (const auto& v : s.vertices) EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-4f);
  for (const auto& t : s.triangles) {
    EXPECT_LT(std::max({t.v0, t.v1, t.v2}), s.vertices.size());
    EXPECT_LT(t.material, s.materials.size());
  }
}

TEST(Loader, Room) {
  scene::Scene s = scene::loadScene(test::referencePath("room/room.gltf"));
  EXPECT_EQ(s.triangles.size(), 2380u);
  EXPECT_NE(findEmissive(s, glm::vec3(0.6f, 0.75f, 1.0f) * 6.0f), nullptr);
  EXPECT_NE(findEmissive(s, glm::vec3(1.0f, 0.8f, 0.55f) * 25.0f), nullptr);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_NEAR(s.cameras[0].yfov, 1.2217305f, 1e-6f);
  glm::vec3 eye(s.cameras[0].worldFromCamera[3]);
  EXPECT_NEAR(glm::length(eye - glm::vec3(-1.2f, 1.5f, 2.3f)), 0.0f, 1e-5f);
  // Rotation is orthonormal.
  glm::mat3 r(s.cameras[0].worldFromCamera);
  glm::mat3 rtr = glm::transpose(r) * r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(rtr[i][j], i == j ? 1.0f : 0.0f, 1e-5f);
  // Closed room 6 x 5 x 2.8 m.
  glm::vec3 extent = s.boundsMax - s.boundsMin;
  EXPECT_GE(extent.x, 5.0f);
  EXPECT_GE(extent.y, 2.8f);
  EXPECT_LE(std::max({extent.x, extent.y, extent.z}), 8.0f);
  // Metals from the README: copper sphere (roughness 0.25) and mirror (0.05).
  int metals = 0;
  for (const auto& m : s.materials) metals += m.metallic > 0.99f;
  EXPECT_GE(metals, 2);
  EXPECT_GT(s.emissive.size(), 0u);
}
