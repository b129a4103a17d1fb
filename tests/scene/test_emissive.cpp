// Emissive-triangle collection on a hand-built scene: power per triangle (luminance, area, pi,
// sides, emissive texture mean), the cdf, and what is left out.
#include <gtest/gtest.h>

#include "scene/emissive.h"

using namespace osr;
namespace gs = osr::gpu::scene;

TEST(Emissive, PowerAndCdf) {
  scene::Scene s;
  // Triangles: a 2 x 1 right triangle (area 1), the same double-sided, a degenerate one
  // and a non-emitting one; then two with an emissive texture (nearest, red | black), one whose
  // uvs lie in the red texel and one in the black texel (left out: its own part of the texture
  // emits nothing).
  s.vertices = {{{0, 0, 0}, 0, {0, 0, 1}, 0},       {{2, 0, 0}, 0, {0, 0, 1}, 0},
                {{0, 1, 0}, 0, {0, 0, 1}, 0},       {{4, 0, 0}, 0, {0, 0, 1}, 0},
                {{0, 0, 0}, 0.1f, {0, 0, 1}, 0.5f}, {{2, 0, 0}, 0.4f, {0, 0, 1}, 0.5f},
                {{0, 1, 0}, 0.1f, {0, 0, 1}, 0.9f}, {{0, 0, 0}, 0.6f, {0, 0, 1}, 0.5f},
                {{2, 0, 0}, 0.9f, {0, 0, 1}, 0.5f}, {{0, 1, 0}, 0.6f, {0, 0, 1}, 0.9f}};
  gs::Material one = scene::defaultMaterial(), two = one, dark = one, textured = one;
  one.emission = glm::vec3(1.0f, 0.0f, 0.0f);
  two.emission = glm::vec3(0.0f, 2.0f, 0.0f);
  two.flags = gs::kMaterialDoubleSided;
  textured.emission = glm::vec3(3.0f, 0.0f, 0.0f);
  textured.emissiveTexture = 0;
  s.materials = {one, two, dark, textured};
  scene::Texture t;
  t.width = 2;
  t.height = 1;
  t.wrap = gs::kTextureNearest;
  t.texels = {0xff0000ffu, 0xff000000u};  // red 1 and 0
  s.textures = {t};
  s.triangles = {{0, 1, 2, 0}, {0, 1, 2, 1}, {0, 1, 3, 0}, {0, 1, 2, 2}, {4, 5, 6, 3}, {7, 8, 9, 3}};
  scene::collectEmissive(s);
  const float pi = 3.14159265f;
  ASSERT_EQ(s.emissive.size(), 3u);  // degenerate and dark left out
  EXPECT_EQ(s.emissive[0].triangle, 0u);
  EXPECT_EQ(s.emissive[1].triangle, 1u);
  EXPECT_EQ(s.emissive[2].triangle, 4u);
  float p0 = 0.2126f * pi, p1 = 0.7152f * 2.0f * pi * 2.0f, p2 = 0.2126f * 3.0f * pi;
  EXPECT_NEAR(s.emissive[0].power, p0, 1e-5f);
  EXPECT_NEAR(s.emissive[1].power, p1, 1e-5f);
  EXPECT_NEAR(s.emissive[2].power, p2, 1e-5f);
  EXPECT_FLOAT_EQ(s.emissive[0].area, 1.0f);
  EXPECT_NEAR(s.emissivePower, p0 + p1 + p2, 1e-5f);
  EXPECT_NEAR(s.emissive[0].cdf, p0 / (p0 + p1 + p2), 1e-6f);
  EXPECT_NEAR(s.emissive[1].cdf, (p0 + p1) / (p0 + p1 + p2), 1e-6f);
  EXPECT_EQ(s.emissive[2].cdf, 1.0f);
  // Idempotent: running again rebuilds, not appends.
  scene::collectEmissive(s);
  EXPECT_EQ(s.emissive.size(), 3u);
}

TEST(Emissive, NoEmittersMeansAnEmptyList) {
  scene::Scene s;
  s.vertices = {
      {{0, 0, 0}, 0, {0, 0, 1}, 0}, {{1, 0, 0}, 0, {0, 0, 1}, 0}, {{0, 1, 0}, 0, {0, 0, 1}, 0}};
  s.materials = {scene::defaultMaterial()};
  s.triangles = {{0, 1, 2, 0}};
  scene::collectEmissive(s);
  EXPECT_TRUE(s.emissive.empty());
  EXPECT_EQ(s.emissivePower, 0.0f);
}
