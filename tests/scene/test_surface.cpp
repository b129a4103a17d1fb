// The C++ twins of lib/scene.glsl (src/scene/surface.cpp) against analytic values: exact texels
// at texel centres, wrap-mode symmetries, the sRGB curve, barycentric corners, a known normal
// map and the alpha cutout of a known texture. (test_scene_probe then holds the GLSL to these.)
#include <gtest/gtest.h>

#include "common/test_paths.h"
#include "scene/surface.h"

using namespace osr;
namespace gs = osr::gpu::scene;

namespace {

uint32_t rgba(uint32_t r, uint32_t g, uint32_t b, uint32_t a) {
  return r | (g << 8) | (b << 16) | (a << 24);
}

// A scene with one 3x2 texture of distinct texels under the given wrap modes.
scene::Scene textureScene(uint32_t wrapS, uint32_t wrapT) {
  scene::Scene s;
  scene::Texture t;
  t.width = 3;
  t.height = 2;
  t.wrap = wrapS | (wrapT << 2);
  for (uint32_t i = 0; i < 6; ++i) t.texels.push_back(rgba(40 * i, 255 - 40 * i, 7 * i, 255));
  s.textures.push_back(t);
  return s;
}

glm::vec4 texelValue(const scene::Scene& s, int x, int y) {
  uint32_t v = s.textures[0].texels[y * 3 + x];
  return glm::vec4(v & 255, (v >> 8) & 255, (v >> 16) & 255, v >> 24) / 255.0f;
}

void expectNear4(glm::vec4 a, glm::vec4 b, const std::string& where) {
  EXPECT_LE(glm::length(a - b), 1e-5f) << where;
}

}  // namespace

TEST(Surface, TexelCentresAreExact) {
  for (uint32_t wrap : {gs::kWrapRepeat, gs::kWrapClamp, gs::kWrapMirror}) {
    scene::Scene s = textureScene(wrap, wrap);
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x)
        expectNear4(scene::sampleTexture(s, 0, {(x + 0.5f) / 3, (y + 0.5f) / 2}),
                    texelValue(s, x, y),
                    "wrap " + std::to_string(wrap) + " texel " + std::to_string(x) + "," +
                        std::to_string(y));
  }
  scene::Scene s = textureScene(0, 0);
  EXPECT_EQ(scene::sampleTexture(s, gs::kNoTexture, {0.3f, 0.3f}), glm::vec4(1.0f));
  // Halfway between two texel centres: their mean.
  expectNear4(scene::sampleTexture(s, 0, {1.0f / 3, 0.25f}),
              0.5f * (texelValue(s, 0, 0) + texelValue(s, 1, 0)), "mid");
}

TEST(Surface, WrapModes) {
  scene::Scene repeat = textureScene(gs::kWrapRepeat, gs::kWrapRepeat);
  scene::Scene clamp = textureScene(gs::kWrapClamp, gs::kWrapClamp);
  scene::Scene mirror = textureScene(gs::kWrapMirror, gs::kWrapMirror);
  for (glm::vec2 uv : {glm::vec2(0.1f, 0.2f), glm::vec2(0.77f, 0.9f), glm::vec2(0.4f, 0.05f)}) {
    std::string where = "uv " + std::to_string(uv.x) + "," + std::to_string(uv.y);
    // Repeat: period 1.
    expectNear4(scene::sampleTexture(repeat, 0, uv + glm::vec2(3, -2)),
                scene::sampleTexture(repeat, 0, uv), where);
    // Mirror: symmetric about 0 and period 2.
    expectNear4(scene::sampleTexture(mirror, 0, -uv), scene::sampleTexture(mirror, 0, uv), where);
    expectNear4(scene::sampleTexture(mirror, 0, uv + glm::vec2(2, 4)),
                scene::sampleTexture(mirror, 0, uv), where);
  }
  // Far outside [0, 1]: still a texel of the texture (values stay in [0, 1]).
  for (const scene::Scene* sc : {&repeat, &clamp, &mirror})
    for (float far : {1e20f, -1e20f, 12345.678f, -7777.25f}) {
      glm::vec4 v = scene::sampleTexture(*sc, 0, {far, -far});
      EXPECT_TRUE(glm::all(glm::greaterThanEqual(v, glm::vec4(0.0f))) &&
                  glm::all(glm::lessThanEqual(v, glm::vec4(1.0f))));
    }
  // Repeat at a large integer offset is still periodic (uvs exact in float, so only the wrap
  // arithmetic could differ).
  expectNear4(scene::sampleTexture(repeat, 0, glm::vec2(0.125f, 0.3125f) + glm::vec2(-4096, 4096)),
              scene::sampleTexture(repeat, 0, {0.125f, 0.3125f}), "large offset");
  // Clamp: beyond the edge is the edge texel.
  expectNear4(scene::sampleTexture(clamp, 0, {-3.0f, 5.0f}), texelValue(clamp, 0, 1),
              "clamp corner");
  expectNear4(scene::sampleTexture(clamp, 0, {7.0f, -1.0f}), texelValue(clamp, 2, 0),
              "clamp corner");
  // Repeat blends across the seam: u = 0 is halfway between the last and the first column.
  expectNear4(scene::sampleTexture(repeat, 0, {0.0f, 0.25f}),
              0.5f * (texelValue(repeat, 2, 0) + texelValue(repeat, 0, 0)), "seam");
}

TEST(Surface, NearestFilter) {
  for (uint32_t wrap : {gs::kWrapRepeat, gs::kWrapClamp, gs::kWrapMirror}) {
    scene::Scene s = textureScene(wrap, wrap);
    s.textures[0].wrap |= gs::kTextureNearest;
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x)
        for (glm::vec2 f :
             {glm::vec2(0.01f, 0.02f), glm::vec2(0.49f, 0.6f), glm::vec2(0.98f, 0.97f)})
          expectNear4(scene::sampleTexture(s, 0, {(x + f.x) / 3, (y + f.y) / 2}),
                      texelValue(s, x, y),
                      "nearest, wrap " + std::to_string(wrap) + " texel " + std::to_string(x) +
                          "," + std::to_string(y));
  }
  scene::Scene s = textureScene(gs::kWrapRepeat, gs::kWrapRepeat);
  s.textures[0].wrap |= gs::kTextureNearest;
  expectNear4(scene::sampleTexture(s, 0, {-0.1f, 0.1f}), texelValue(s, 2, 0), "nearest repeat");
}

TEST(Surface, SrgbToLinear) {
  glm::vec3 l = scene::srgbToLinear({0.0f, 0.04045f, 1.0f});
  EXPECT_FLOAT_EQ(l.x, 0.0f);
  EXPECT_NEAR(l.y, 0.04045f / 12.92f, 1e-7f);
  EXPECT_NEAR(l.z, 1.0f, 1e-6f);
  EXPECT_NEAR(scene::srgbToLinear(glm::vec3(0.5f)).x, 0.2140411f, 1e-6f);
}

namespace {

// One triangle in the z = 0 plane with uv = (x, y): tangent +X, bitangent +Y, normal +Z.
scene::Scene flatTriangle() {
  scene::Scene s;
  s.vertices = {
      {{0, 0, 0}, 0, {0, 0, 1}, 0}, {{2, 0, 0}, 1, {0, 0, 1}, 0}, {{0, 2, 0}, 0, {0, 0, 1}, 1}};
  s.triangles = {{0, 1, 2, 0}};
  s.materials = {scene::defaultMaterial()};
  return s;
}

}  // namespace

TEST(Surface, SurfaceAtInterpolatesAndAppliesTheNormalMap) {
  scene::Scene s = flatTriangle();
  scene::SurfaceSample c = scene::surfaceAt(s, 0, {1.0f, 0.0f});
  EXPECT_EQ(c.position, glm::vec3(2, 0, 0));
  EXPECT_EQ(c.uv, glm::vec4(1, 0, 1, 0));  // no TEXCOORD_1: set 1 reads set 0
  scene::SurfaceSample m = scene::surfaceAt(s, 0, {0.25f, 0.5f});
  EXPECT_EQ(m.position, glm::vec3(0.5f, 1.0f, 0));
  EXPECT_EQ(m.geometricNormal, glm::vec3(0, 0, 1));
  EXPECT_EQ(m.shadingNormal, glm::vec3(0, 0, 1));
  // Normal map texel (255, 128, 128) encodes tangent-space (1, 1/255, 1/255): the normal tilts
  // to +X (the tangent), scaled in xy by normalScale.
  scene::Texture t;
  t.width = t.height = 1;
  t.texels = {rgba(255, 128, 128, 255)};
  s.textures.push_back(t);
  s.materials[0].normalTexture = 0;
  s.materials[0].normalScale = 0.5f;
  float e = 2.0f * 128 / 255 - 1;
  glm::vec3 expected = glm::normalize(glm::vec3(0.5f, 0.5f * e, e));
  glm::vec3 n = scene::surfaceAt(s, 0, {0.25f, 0.5f}).shadingNormal;
  EXPECT_LE(glm::length(n - expected), 1e-5f) << n.x << " " << n.y << " " << n.z;
  // Mirrored uv (u decreasing along +X) mirrors the tangent.
  std::swap(s.vertices[0].u, s.vertices[1].u);
  s.vertices[2].u = 1;
  n = scene::surfaceAt(s, 0, {0.25f, 0.5f}).shadingNormal;
  EXPECT_LT(n.x, -0.3f);
}

TEST(Surface, MaterialTexturesMultiplyFactors) {
  scene::Scene s = flatTriangle();
  scene::Texture t;
  t.width = t.height = 1;
  t.texels = {rgba(255, 128, 64, 51)};
  s.textures.push_back(t);
  gs::Material& mat = s.materials[0];
  mat.baseColor = glm::vec4(0.5f, 1.0f, 1.0f, 0.8f);
  mat.baseColorTexture = mat.metallicRoughnessTexture = mat.emissiveTexture = 0;
  mat.transmissionTexture = mat.specularTexture = mat.specularColorTexture = 0;
  mat.emission = glm::vec3(10.0f);
  mat.metallic = 0.5f;
  mat.roughness = 0.5f;
  mat.transmission = 1.0f;
  scene::SurfaceMaterial m = scene::surfaceAt(s, 0, {0.2f, 0.2f}).m;
  glm::vec3 lin = scene::srgbToLinear(glm::vec3(1.0f, 128 / 255.0f, 64 / 255.0f));
  EXPECT_LE(glm::length(m.baseColor - glm::vec3(0.5f, 1, 1) * lin), 1e-6f);
  EXPECT_NEAR(m.alpha, 0.8f * 0.2f, 1e-6f);
  EXPECT_NEAR(m.roughness, 0.5f * 128 / 255.0f, 1e-6f);  // G
  EXPECT_NEAR(m.metallic, 0.5f * 64 / 255.0f, 1e-6f);    // B
  EXPECT_NEAR(m.transmission, 1.0f, 1e-6f);              // R
  EXPECT_NEAR(m.specular, 0.2f, 1e-6f);                  // A
  EXPECT_LE(glm::length(m.emission - 10.0f * lin), 1e-5f);
  EXPECT_LE(glm::length(m.specularColor - lin), 1e-6f);
}

TEST(Surface, AlphaCutoutOfTheMaskFile) {
  scene::Scene s = scene::loadScene(test::dataPath("scene/alpha_mask.gltf"));
  // Quad triangle 0 has uv = (b1 + b2, 1 - b2) over a 2x2 clamped checker: texel (1, 1) opaque,
  // texel (1, 0) transparent. Mask material (cutoff 0.4) is triangles 0-1, opaque 2-3, blend
  // (alpha 0.3, stochastic) 4-5.
  glm::vec2 opaque(0.5f, 0.25f);       // uv (0.75, 0.75)
  glm::vec2 transparent(0.0f, 0.75f);  // uv (0.75, 0.25)
  glm::vec3 o(0.0f), inv(1.0f);
  EXPECT_FALSE(scene::alphaCutout(s, 0, opaque, o, inv));
  EXPECT_TRUE(scene::alphaCutout(s, 0, transparent, o, inv));
  EXPECT_FALSE(scene::alphaCutout(s, 2, transparent, o, inv));
  EXPECT_EQ(scene::coverage(s, 0, opaque), 1.0f);
  EXPECT_EQ(scene::coverage(s, 0, transparent), 0.0f);
  EXPECT_EQ(scene::coverage(s, 2, transparent), 1.0f);
  EXPECT_NEAR(scene::coverage(s, 4, opaque), 0.3f, 1e-6f);
  // Blend: rays pass with probability 1 - alpha, decided by a hash of the ray and triangle
  // (the same ray always decides alike). 20000 rays: standard error 0.0032.
  int passed = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    glm::vec3 origin(0.001f * float(i), 1.0f, -2.0f), invDir(1.0f, 1.0f / (1.0f + 1e-4f * float(i)), 3.0f);
    bool cut = scene::alphaCutout(s, 4, opaque, origin, invDir);
    EXPECT_EQ(cut, scene::alphaCutout(s, 4, opaque, origin, invDir));
    passed += cut ? 1 : 0;
  }
  EXPECT_NEAR(double(passed) / n, 0.7, 0.015);
}
