// The glTF loader on the reference scenes and on hand-made files covering each feature, and
// its refusal of bad input (InputError naming the file).
#include <gtest/gtest.h>

#include <glm/gtc/packing.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <random>

#include "common/error.h"
#include "common/test_paths.h"
#include "scene/scene.h"
#include "scene/surface.h"
#include "scene/scene_test_util.h"

using namespace osr;
using test::expectNear;
using test::hasWarning;
namespace gs = osr::gpu::scene;

namespace {

// Files of this process only: the fixed names in gtest's shared TempDir() collided with
// the same suite run at the same time from another checkout or build folder.
std::string tempPrefix() {
  return osr::test::tempDir("scene_loader").string() + "/";
}

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
  for (size_t i = 1; i < s.emissive.size(); ++i)
    EXPECT_GE(s.emissive[i].cdf, s.emissive[i - 1].cdf);
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
  // Metals from the README: copper sphere (roughness 0.25) and mirror (0.05); metallicFactor
  // absent in the file means 1, roughnessFactor absent means 1.
  ASSERT_EQ(s.materials.size(), 8u);
  EXPECT_EQ(s.materials[6].metallic, 1.0f);
  EXPECT_FLOAT_EQ(s.materials[6].roughness, 0.25f);
  EXPECT_EQ(s.materials[7].metallic, 1.0f);
  EXPECT_FLOAT_EQ(s.materials[7].roughness, 0.05f);
  EXPECT_EQ(s.materials[1].metallic, 0.0f);
  EXPECT_EQ(s.materials[1].roughness, 1.0f);
  // Emissive triangles are exactly those of the sky and lamp materials (2 and 3), with power
  // luminance x area x pi x 2 (double-sided) each.
  size_t emissiveTriangles = 0;
  for (const auto& t : s.triangles) emissiveTriangles += t.material == 2 || t.material == 3;
  EXPECT_EQ(s.emissive.size(), emissiveTriangles);
  double total = 0.0;
  for (const auto& e : s.emissive) {
    const gs::Triangle& t = s.triangles[e.triangle];
    glm::vec3 p0 = s.vertices[t.v0].position, p1 = s.vertices[t.v1].position,
              p2 = s.vertices[t.v2].position;
    float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
    EXPECT_NEAR(e.area, area, 1e-6f);
    EXPECT_NEAR(e.power,
                scene::luminance(s.materials[t.material].emission) * area * 3.14159265f * 2.0f,
                1e-4f * e.power);
    total += e.power;
  }
  EXPECT_NEAR(s.emissivePower, total, 1e-4 * total);
}

namespace {

std::string data(const std::string& name) {
  return test::dataPath("scene/" + name);
}

void expectInputError(const std::string& path, const std::string& part) {
  test::expectInputError([](const std::string& p) { scene::loadScene(p); }, path, part);
}

glm::vec3 faceNormal(const scene::Scene& s, const gs::Triangle& t) {
  glm::vec3 p0 = s.vertices[t.v0].position, p1 = s.vertices[t.v1].position,
            p2 = s.vertices[t.v2].position;
  return glm::normalize(glm::cross(p1 - p0, p2 - p0));
}

}  // namespace

TEST(Loader, NodeHierarchyMatrixTrsMirrorAndNonUniformScale) {
  scene::Scene s = scene::loadScene(data("hierarchy.gltf"));
  ASSERT_EQ(s.triangles.size(), 5u);
  // Child quad: TRS (rotate 90 deg about Z, translate +Y) under a matrix (scale 2, +10 X).
  // Quad corners (0,0,0), (1,0,0), (1,1,0) -> (10,2,0), (10,4,0), (8,4,0).
  const gs::Triangle& t0 = s.triangles[0];
  expectNear(s.vertices[t0.v0].position, {10, 2, 0});
  expectNear(s.vertices[t0.v1].position, {10, 4, 0});
  expectNear(s.vertices[t0.v2].position, {8, 4, 0});
  // Mirrored quad (scale -1 in X): winding flipped so the face normal stays +Z.
  const gs::Triangle& t2 = s.triangles[2];
  expectNear(faceNormal(s, t2), {0, 0, 1});
  expectNear(s.vertices[t2.v0].position, {0, 0, 5});
  // Non-uniform scale (1,2,1) on a face with normal (0,1,1)/sqrt2: inverse transpose gives
  // (0,1,2)/sqrt5, the normal of the stretched face.
  expectNear(s.vertices[s.triangles[4].v0].normal, glm::normalize(glm::vec3(0, 1, 2)));
  // Invariant: each flat face's vertex normals equal its geometric normal after transforms.
  for (const auto& t : s.triangles) {
    glm::vec3 n = faceNormal(s, t);
    for (uint32_t v : {t.v0, t.v1, t.v2}) expectNear(s.vertices[v].normal, n);
  }
  expectNear(s.boundsMin, {-1, 0, -6});  // the slanted face reaches z = -1 - 5
  expectNear(s.boundsMax, {10, 4, 5});
  EXPECT_EQ(s.materials.size(), 1u);  // the default material
  EXPECT_EQ(s.materials[0].metallic, 1.0f);
}

TEST(Loader, NonIndexedWithGeneratedNormals) {
  scene::Scene s = scene::loadScene(data("nonindexed.gltf"));
  ASSERT_EQ(s.triangles.size(), 2u);
  ASSERT_EQ(s.vertices.size(), 6u);
  expectNear(s.vertices[s.triangles[0].v1].position, {1, 0, 0});
  for (int k = 0; k < 3; ++k) {
    expectNear(s.vertices[3 * 0 + k].normal, {0, 0, 1});
    expectNear(s.vertices[3 * 1 + k].normal, {-1, 0, 0});
  }
}

TEST(Loader, IndexComponentTypes) {
  scene::Scene s = scene::loadScene(data("index_types.gltf"));  // u8, u16, u32; external .bin
  ASSERT_EQ(s.triangles.size(), 6u);
  for (int q = 0; q < 3; ++q)
    for (int t = 0; t < 2; ++t) {
      const gs::Triangle& a = s.triangles[2 * q + t];
      const gs::Triangle& ref = s.triangles[t];
      for (int k = 0; k < 3; ++k) {
        uint32_t va = (&a.v0)[k], vr = (&ref.v0)[k];
        expectNear(s.vertices[va].position, s.vertices[vr].position + glm::vec3(2.0f * q, 0, 0));
      }
    }
}

TEST(Loader, TexturesFromFilesAndDataUris) {
  scene::Scene s = scene::loadScene(data("textured.gltf"));
  // Five glTF textures; the emissive one is shared with specularColor, the specular one with
  // transmission: each decoded once.
  ASSERT_EQ(s.textures.size(), 5u);
  const gs::Material& m = s.materials[0];
  ASSERT_GE(m.baseColorTexture, 0);
  const scene::Texture& base = s.textures[m.baseColorTexture];  // checker.png, 4x4
  EXPECT_EQ(base.width, 4u);
  EXPECT_EQ(base.height, 4u);
  EXPECT_EQ(base.texels[0], 0xFF0000FFu);  // red, opaque; R in the low byte
  EXPECT_EQ(base.texels[1], 0x80FF0000u);  // blue, alpha 128
  EXPECT_EQ(base.wrap, gs::kWrapRepeat | (gs::kWrapRepeat << 2));
  const scene::Texture& mr = s.textures[m.metallicRoughnessTexture];  // data: URI, 2x2
  EXPECT_EQ(mr.width, 2u);
  EXPECT_EQ(mr.texels[1], 0xFF808000u);
  EXPECT_EQ(mr.wrap, gs::kWrapClamp | (gs::kWrapMirror << 2));
  EXPECT_EQ(s.textures[m.normalTexture].wrap,
            gs::kWrapMirror | (gs::kWrapClamp << 2) | gs::kTextureNearest);  // magFilter NEAREST
  EXPECT_EQ(m.emissiveTexture, m.specularColorTexture);
  EXPECT_EQ(m.specularTexture, m.transmissionTexture);
  EXPECT_NE(m.emissiveTexture, m.specularTexture);
  EXPECT_FLOAT_EQ(m.normalScale, 0.7f);
  EXPECT_FLOAT_EQ(m.specular, 0.9f);
  EXPECT_FLOAT_EQ(m.transmission, 0.6f);
  expectNear(m.specularColor, {1, 0.5f, 0.25f});
  expectNear(glm::vec3(m.baseColor), {1, 0.5f, 1});
  // Emissive power: each triangle's mean emission over its own part of the texture (texels
  // (255, 128, 0) and (0, 128, 255), bilinear, repeated over uvs -0.5..1.5), against a dense
  // 64 x 64 grid of surfaceAt samples; two unit quads, one side each.
  ASSERT_EQ(s.emissive.size(), 4u);
  for (const gs::EmissiveTriangle& e : s.emissive) {
    double sum = 0;
    const int n = 64;
    for (int j = 0; j < n; ++j)
      for (int k = 0; j + k < n; ++k)
        sum += 2.0 * scene::luminance(scene::surfaceAt(s, e.triangle, {(k + 0.33f) / n, (j + 0.33f) / n}).m.emission);
    double lum = sum / (double(n) * (n + 1));
    EXPECT_NEAR(e.power, lum * 3.14159265 * e.area, 0.02 * e.power) << "triangle " << e.triangle;
  }
}

TEST(Loader, SixteenBitTexturesRoundTo8Bits) {
  scene::Scene s = scene::loadScene(data("texture16.gltf"));
  ASSERT_EQ(s.textures.size(), 1u);
  ASSERT_EQ(s.textures[0].texels.size(), 2u);
  EXPECT_EQ(s.textures[0].texels[0], 0xFFFFAB12u);
  EXPECT_EQ(s.textures[0].texels[1], 0x7F800101u);  // 0x00FF and 0x0100 round to 1
}

TEST(Loader, DegenerateAttributesWarnAndFallBack) {
  scene::Scene s = scene::loadScene(data("degenerate_attributes.gltf"));
  EXPECT_TRUE(hasWarning(s, "EXT_texture_webp"));
  EXPECT_TRUE(hasWarning(s, "no PNG/JPEG source"));
  EXPECT_TRUE(hasWarning(s, "TEXCOORD_0"));
  EXPECT_TRUE(hasWarning(s, "NORMAL"));
  EXPECT_EQ(s.materials[0].baseColorTexture, gs::kNoTexture);
  EXPECT_TRUE(s.textures.empty());
  const gs::Vertex& v1 = s.vertices[s.triangles[0].v1];
  EXPECT_EQ(v1.u, 0.0f);
  EXPECT_EQ(v1.normal, glm::vec3(0.0f));  // the shaders use the face normal for it
}

TEST(Loader, TextureTransformIsBakedIntoUvs) {
  scene::Scene s = scene::loadScene(data("texture_transform.gltf"));
  ASSERT_EQ(s.triangles.size(), 6u);
  auto uv = [&](uint32_t tri, int corner) {
    const gs::Vertex& v = s.vertices[(&s.triangles[tri].v0)[corner]];
    return glm::vec2(v.u, v.v);
  };
  auto near2 = [](glm::vec2 a, glm::vec2 b) { return glm::length(a - b) < 1e-5f; };
  // Quad uvs (0,0), (1,0), (1,1) on triangle 0. Offset (0.5, 0), scale 0.5:
  EXPECT_TRUE(near2(uv(0, 0), {0.5f, 0.0f}));
  EXPECT_TRUE(near2(uv(0, 1), {1.0f, 0.0f}));
  EXPECT_TRUE(near2(uv(0, 2), {1.0f, 0.5f}));
  // The extension's example: lower-left quadrant (u < 0.5, v > 0.5 with v down), rotated.
  EXPECT_TRUE(near2(uv(2, 0), {0.0f, 1.0f}));
  EXPECT_TRUE(near2(uv(2, 1), {0.0f, 0.5f}));
  EXPECT_TRUE(near2(uv(2, 2), {0.5f, 0.5f}));
  // Slots that disagree: the base colour's transform in the vertex uvs, the normal map's
  // (identity) in the uv1 slot, the emission's third one warned and read as the base colour's.
  EXPECT_TRUE(hasWarning(s, "different KHR_texture_transform"));
  EXPECT_TRUE(near2(uv(4, 1), {1.0f, 0.0f}));
  const gs::Material& two = s.materials[2];
  EXPECT_EQ(two.baseColorTexture & gs::kTextureTexCoord1, 0);
  EXPECT_NE(two.normalTexture & gs::kTextureTexCoord1, 0);
  EXPECT_EQ(two.emissiveTexture & gs::kTextureTexCoord1, 0);
  ASSERT_EQ(s.attributes.size(), s.vertices.size());
  EXPECT_TRUE(near2(s.attributes[s.triangles[4].v1].uv1, {1.0f, 0.0f}));
  EXPECT_TRUE(near2(s.attributes[s.triangles[4].v2].uv1, {1.0f, 1.0f}));
  EXPECT_FALSE(hasWarning(s, "unsupported extension KHR_texture_transform"));
}

TEST(Loader, VertexColorsAndSecondUvSet) {
  scene::Scene s = scene::loadScene(data("vertex_attributes.gltf"));
  ASSERT_EQ(s.vertices.size(), 12u);
  ASSERT_EQ(s.attributes.size(), s.vertices.size());
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_EQ(s.materials[0].baseColorTexture, 0 | gs::kTextureTexCoord1);
  EXPECT_EQ(s.materials[0].emissiveTexture, 0);
  auto color = [&](uint32_t v) {
    glm::vec2 rg = glm::unpackHalf2x16(s.attributes[v].colorRG),
              ba = glm::unpackHalf2x16(s.attributes[v].colorBA);
    return glm::vec4(rg, ba);
  };
  auto near4 = [](glm::vec4 a, glm::vec4 b) { return glm::length(a - b) < 2e-3f; };
  // Normalized unsigned bytes, floats (RGB: alpha 1), normalized unsigned shorts.
  EXPECT_TRUE(near4(color(0), {1, 0, 0, 1}));
  EXPECT_TRUE(near4(color(2), {0, 0, 1, 128 / 255.0f}));
  EXPECT_TRUE(near4(color(4), {1, 0.5f, 0.25f, 1}));
  EXPECT_TRUE(near4(color(9), {0, 1, 0, 32768 / 65535.0f}));
  // TEXCOORD_1 = TEXCOORD_0 mirrored in u, then its slot's transform (offset 0.5, scale 0.5 in
  // u); TEXCOORD_0 keeps its own (none). Without TEXCOORD_1, uv1 = uv0.
  EXPECT_EQ(s.attributes[0].uv1, glm::vec2(1.0f, 1.0f));
  EXPECT_EQ(s.attributes[1].uv1, glm::vec2(0.5f, 1.0f));
  EXPECT_EQ(glm::vec2(s.vertices[1].u, s.vertices[1].v), glm::vec2(1.0f, 1.0f));
  EXPECT_EQ(s.attributes[5].uv1, glm::vec2(s.vertices[5].u, s.vertices[5].v));
  // Base colour through set 1 (blue texel at uv1 (0.9, 0.9)) times COLOR_0; emission through
  // set 0 (red texel at uv (0.2, 0.9)); alpha from COLOR_0.
  scene::SurfaceSample p = scene::surfaceAt(s, 0, {0.1f, 0.1f});
  EXPECT_LE(glm::length(p.m.baseColor - glm::vec3(0, 0, 0.1f)), 2e-3f);
  EXPECT_LE(glm::length(p.m.emission - glm::vec3(1, 0, 0)), 1e-5f);
  EXPECT_NEAR(p.m.alpha, 0.9f + 0.1f * 128 / 255.0f, 2e-3f);
  // A file without them keeps no attribute array (the shaders read none).
  EXPECT_TRUE(scene::loadScene(data("textured.gltf")).attributes.empty());
}

TEST(Loader, AlphaModes) {
  scene::Scene s = scene::loadScene(data("alpha_mask.gltf"));
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_TRUE(s.materials[0].flags & gs::kMaterialAlphaMask);
  EXPECT_FLOAT_EQ(s.materials[0].alphaCutoff, 0.4f);
  EXPECT_EQ(s.materials[1].flags & (gs::kMaterialAlphaMask | gs::kMaterialAlphaBlend), 0u);
  EXPECT_TRUE(s.materials[2].flags & gs::kMaterialAlphaBlend);
  EXPECT_FLOAT_EQ(s.materials[2].alphaCutoff, 0.5f);
  EXPECT_FALSE(hasWarning(s, "BLEND"));  // stochastic transparency: nothing to warn about
}

TEST(Loader, PunctualLights) {
  scene::Scene s = scene::loadScene(data("lights.gltf"));
  ASSERT_EQ(s.lights.size(), 3u);
  const gs::PunctualLight &point = s.lights[0], &spot = s.lights[1], &sun = s.lights[2];
  // 683 cd = 1 W/sr (683 lm/W), times the colour.
  EXPECT_EQ(point.type, gs::kLightPoint);
  expectNear(point.intensity, {1, 0.5f, 0.25f});
  expectNear(point.position, {1, 2, 3});
  EXPECT_FLOAT_EQ(point.range, 10.0f);
  EXPECT_EQ(spot.type, gs::kLightSpot);
  expectNear(spot.intensity, {2, 2, 2});
  expectNear(spot.position, {0, 4, 0});
  expectNear(spot.direction, {0, -1, 0});  // node rotated -90 deg about X: -Z -> -Y
  EXPECT_NEAR(spot.cosInner, std::cos(0.2f), 1e-6f);
  EXPECT_NEAR(spot.cosOuter, std::cos(0.5f), 1e-6f);
  EXPECT_EQ(sun.type, gs::kLightDirectional);
  expectNear(sun.intensity, glm::vec3(0.5f, 0.5f, 1.0f) * 0.01f);
  expectNear(sun.direction, {0, 0, -1});
  EXPECT_TRUE(s.warnings.empty());
}

TEST(Loader, MaterialExtensionsWarningsAndEmissivePower) {
  scene::Scene s = scene::loadScene(data("materials.gltf"));
  EXPECT_EQ(s.triangles.size(), 8u);  // the LINES primitive is skipped
  EXPECT_TRUE(hasWarning(s, "KHR_materials_dispersion"));
  int dispersion = 0;  // named in extensionsUsed and by a material: warned once
  for (const auto& w : s.warnings)
    dispersion += w.find("KHR_materials_dispersion") != std::string::npos;
  EXPECT_EQ(dispersion, 1);
  EXPECT_TRUE(hasWarning(s, "mode 1"));
  ASSERT_EQ(s.materials.size(), 4u);  // three + the default for the primitive without one
  const gs::Material& glass = s.materials[0];
  EXPECT_FLOAT_EQ(glass.ior, 1.33f);
  EXPECT_FLOAT_EQ(glass.transmission, 1.0f);
  EXPECT_FLOAT_EQ(glass.specular, 0.5f);
  expectNear(glass.specularColor, {0.2f, 0.4f, 0.6f});
  EXPECT_FLOAT_EQ(glass.roughness, 0.1f);
  EXPECT_FLOAT_EQ(glass.metallic, 0.0f);
  expectNear(s.materials[1].emission, glm::vec3(1, 0.5f, 0.25f) * 40.0f, 1e-4f);
  EXPECT_EQ(s.triangles[6].material, 3u);
  EXPECT_EQ(s.materials[3].baseColor, glm::vec4(1.0f));
  // Emissive triangles: the lamp (area 2 x 3, double-sided: both sides count) and the dim quad
  // (area 1, one side).
  ASSERT_EQ(s.emissive.size(), 4u);
  const float pi = 3.14159265f;
  float lampLum = scene::luminance(glm::vec3(1, 0.5f, 0.25f) * 40.0f);
  float lamp = lampLum * 6.0f * pi * 2.0f, dim = 0.5f * 1.0f * pi;
  EXPECT_NEAR(s.emissivePower, lamp + dim, 1e-3f * (lamp + dim));
  EXPECT_NEAR(s.emissive[0].power + s.emissive[1].power, lamp, 1e-3f * lamp);
  EXPECT_NEAR(s.emissive[0].area + s.emissive[1].area, 6.0f, 1e-5f);
  EXPECT_NEAR(s.emissive[1].cdf, lamp / (lamp + dim), 1e-5f);
  EXPECT_FLOAT_EQ(s.emissive[3].cdf, 1.0f);
}

TEST(Loader, IridescenceFieldsAndTextures) {
  scene::Scene s = scene::loadScene(data("iridescence.gltf"));
  EXPECT_FALSE(hasWarning(s, "iridescence"));
  ASSERT_EQ(s.materials.size(), 3u);
  const gs::Material &film = s.materials[0], &draft = s.materials[1], &defaults = s.materials[2];
  EXPECT_FLOAT_EQ(film.iridescence, 0.8f);
  EXPECT_FLOAT_EQ(film.iridescenceIor, 1.8f);
  EXPECT_FLOAT_EQ(film.iridescenceThicknessMinimum, 250.0f);
  EXPECT_FLOAT_EQ(film.iridescenceThicknessMaximum, 650.0f);
  // The factor texture (R) on TEXCOORD_0, the thickness texture (G) on TEXCOORD_1.
  ASSERT_GE(film.iridescenceTexture, 0);
  ASSERT_GE(film.iridescenceThicknessTexture, 0);
  EXPECT_EQ(film.iridescenceTexture & gs::kTextureTexCoord1, 0);
  EXPECT_NE(film.iridescenceThicknessTexture & gs::kTextureTexCoord1, 0);
  const scene::Texture& factor = s.textures[film.iridescenceTexture & gs::kTextureIndexMask];
  const scene::Texture& thickness =
      s.textures[film.iridescenceThicknessTexture & gs::kTextureIndexMask];
  ASSERT_EQ(factor.width, 2u);
  EXPECT_EQ(factor.texels[0] & 0xFFu, 128u);
  ASSERT_EQ(thickness.height, 2u);
  EXPECT_EQ((thickness.texels[1] >> 8) & 0xFFu, 255u);
  EXPECT_FLOAT_EQ(draft.iridescence, 1.0f);
  EXPECT_FLOAT_EQ(draft.iridescenceIor, 1.6f);  // the draft's "iridescenceIOR"
  // The extension's defaults: factor 0 (no film), ior 1.3, 100-400 nm, no textures.
  EXPECT_FLOAT_EQ(defaults.iridescence, 0.0f);
  EXPECT_FLOAT_EQ(defaults.iridescenceIor, 1.3f);
  EXPECT_FLOAT_EQ(defaults.iridescenceThicknessMinimum, 100.0f);
  EXPECT_FLOAT_EQ(defaults.iridescenceThicknessMaximum, 400.0f);
  EXPECT_EQ(defaults.iridescenceTexture, gs::kNoTexture);
  EXPECT_EQ(defaults.iridescenceThicknessTexture, gs::kNoTexture);
  // A material without the extension has no film either.
  EXPECT_FLOAT_EQ(scene::loadScene(data("textured.gltf")).materials[0].iridescence, 0.0f);
}

TEST(Loader, BinaryGlbWithEmbeddedImage) {
  scene::Scene s = scene::loadScene(data("quad.glb"));
  ASSERT_EQ(s.triangles.size(), 2u);
  expectNear(s.vertices[s.triangles[0].v1].position, {1, 0, -1});
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].texels[0], 0xFF1E140Au);  // (10, 20, 30, 255)
}

TEST(Loader, SparseAccessors) {
  scene::Scene s = scene::loadScene(data("sparse.gltf"));
  ASSERT_EQ(s.triangles.size(), 4u);
  // Over a buffer view: vertex 2 replaced by (1, 1, 1), the others kept.
  expectNear(s.vertices[s.triangles[0].v1].position, {1, 0, 0});
  expectNear(s.vertices[s.triangles[0].v2].position, {1, 1, 1});
  // Over zeros: vertex 0 stays (0, 0, 0), 1..3 from the sparse values; node moved to z = 2.
  const gs::Triangle& t = s.triangles[2];
  expectNear(s.vertices[t.v0].position, {0, 0, 2});
  expectNear(s.vertices[t.v2].position, {1, 1, 2});
}

TEST(Loader, QuantizedAttributes) {
  scene::Scene s = scene::loadScene(data("quantized.gltf"));
  EXPECT_TRUE(s.warnings.empty());  // KHR_mesh_quantization is supported
  ASSERT_EQ(s.triangles.size(), 2u);
  const gs::Triangle& t = s.triangles[0];
  expectNear(s.vertices[t.v1].position, {1, 0, 0});  // int16 1000 x node scale 0.001
  expectNear(s.vertices[t.v2].position, {1, 1, 0});
  expectNear(s.vertices[t.v0].normal, {0, 0, 1});  // int8 127 normalized
  EXPECT_NEAR(s.vertices[t.v0].v, 1.0f, 1e-6f);    // uint16 65535 normalized
  EXPECT_NEAR(s.vertices[t.v2].u, 1.0f, 1e-6f);
}

// ---- Bad input: InputError, one line, starting with the file name ----------------------------

TEST(LoaderBadInput, EachKindNamesTheFileAndTheProblem) {
  const std::pair<const char*, const char*> cases[] = {
      {"no_such_file.gltf", "file not found"},
      {"bad_truncated.glb", "truncated"},
      {"bad_json.gltf", "parse error"},
      {"bad_accessor_range.gltf", "out of range"},
      {"bad_buffer_view_range.gltf", "out of range"},
      {"bad_index.gltf", "past the vertex count"},
      {"bad_nan.gltf", "not finite"},
      {"bad_inf.gltf", "not finite"},
      {"bad_missing_texture.gltf", "missing texture image"},
      {"bad_no_triangles.gltf", "no triangles"},
      {"bad_missing_bin.gltf", "not found"},
      {"bad_sparse_index.gltf", "past the accessor count"},
  };
  for (const auto& [file, problem] : cases) expectInputError(data(file), problem);
  expectInputError(test::dataPath("scene"), "directory");
}

// A pipe was opened and waited on forever, a device (/dev/zero) read until memory ran out:
// both are refused before they are opened.
TEST(LoaderBadInput, DevicesAndPipesAreRefusedUnopened) {
  expectInputError(test::makeFifo("scene_loader", "pipe.gltf"), "not a regular file");
  expectInputError("/dev/null", "not a regular file");
}

// The same for the files a .gltf names: a buffer URI naming a folder was "out of memory
// loading the scene", one naming a pipe hung.
TEST(LoaderBadInput, BuffersThatAreNoRegularFileAreRefused) {
  const std::filesystem::path dir = test::tempDir("scene_loader_buffers");
  const std::filesystem::path gltf = dir / "cornell.gltf", bin = dir / "cornell.bin";
  std::filesystem::copy_file(test::referencePath("cornell/cornell.gltf"), gltf,
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::remove_all(bin);
  std::filesystem::create_directory(bin);
  expectInputError(gltf.string(), "cornell.bin : is a directory");
  std::filesystem::remove_all(bin);
  test::makeFifo("scene_loader_buffers", "cornell.bin");
  expectInputError(gltf.string(), "cornell.bin : not a regular file");
}

namespace {

std::string tempFile(const std::string& name, const std::vector<unsigned char>& bytes) {
  std::string path = tempPrefix() + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!bytes.empty()) std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  return path;
}

std::vector<unsigned char> readFile(const std::string& path) {
  std::vector<unsigned char> bytes;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  for (int c; (c = std::fgetc(f)) != EOF;) bytes.push_back(static_cast<unsigned char>(c));
  std::fclose(f);
  return bytes;
}

}  // namespace

TEST(LoaderBadInput, EmptyAndJunkFiles) {
  expectInputError(tempFile("empty.gltf", {}), "empty");
  expectInputError(tempFile("junk.glb", {'g', 'l', 'T', 'F', 2, 0, 0, 0, 9}), "truncated");
  std::vector<unsigned char> junk(300);
  for (size_t i = 0; i < junk.size(); ++i) junk[i] = static_cast<unsigned char>(i * 7 + 3);
  std::string path = tempFile("junk.gltf", junk);
  EXPECT_THROW(scene::loadScene(path), InputError);
}

// Every prefix of a valid .glb, with the header's total length patched to match so that the
// chunk checks (not the length check) must catch it: InputError or a valid load, never a crash.
TEST(LoaderBadInput, EveryTruncationOfAGlb) {
  std::vector<unsigned char> glb = readFile(data("quad.glb"));
  ASSERT_GT(glb.size(), 100u);
  int refused = 0;
  for (size_t n = 12; n < glb.size(); n += 5) {
    std::vector<unsigned char> cut(glb.begin(), glb.begin() + n);
    uint32_t length = uint32_t(n);
    std::memcpy(cut.data() + 8, &length, 4);
    std::string path = tempFile("cut.glb", cut);
    try {
      scene::loadScene(path);
    } catch (const InputError& e) {
      ++refused;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(refused, 0);
}

namespace {

// nonindexed.gltf (one mesh, buffer in a data: URI) with its node list replaced.
std::string withNodes(const std::string& name, const nlohmann::json& nodes,
                      const nlohmann::json& roots) {
  std::ifstream in(data("nonindexed.gltf"));
  nlohmann::json doc = nlohmann::json::parse(in);
  doc["nodes"] = nodes;
  doc["scenes"][0]["nodes"] = roots;
  std::string path = tempPrefix() + name;
  std::ofstream(path) << doc.dump();
  return path;
}

}  // namespace

TEST(Loader, DeepHierarchyNeedsNoDeepStack) {
  // 100k nested nodes (a recursive walk would need tens of MiB of stack), each translating by
  // 2^-17 in x, which float sums exactly; the mesh at the bottom.
  const int depth = 100000;
  const double step = 1.0 / 131072;
  nlohmann::json nodes = nlohmann::json::array();
  for (int i = 0; i < depth - 1; ++i)
    nodes.push_back({{"children", {i + 1}}, {"translation", {step, 0, 0}}});
  nodes.push_back({{"mesh", 0}});
  scene::Scene s = scene::loadScene(withNodes("deep.gltf", nodes, {0}));
  EXPECT_EQ(s.vertices[0].position.x, float((depth - 1) * step));
}

TEST(LoaderBadInput, NodeCyclesAndSecondParents) {
  nlohmann::json cycle = {{{"children", {1}}}, {{"children", {0}}, {"mesh", 0}}};
  expectInputError(withNodes("cycle.gltf", cycle, {0}), "reached twice");
  nlohmann::json shared = {{{"children", {2}}}, {{"children", {2}}}, {{"mesh", 0}}};
  expectInputError(withNodes("shared.gltf", shared, {0, 1}), "reached twice");
  expectInputError(withNodes("dangling.gltf", {{{"children", {7}}}}, {0}), "node 7 does not exist");
}

TEST(LoaderBadInput, HugeCountWithoutBufferView) {
  std::ifstream in(data("nonindexed.gltf"));
  nlohmann::json doc = nlohmann::json::parse(in);
  doc["accessors"][0].erase("bufferView");  // zeros: nothing bounds the count but the count
  doc["accessors"][0].erase("min");
  doc["accessors"][0].erase("max");
  doc["accessors"][0]["count"] = 1ll << 40;
  std::string path = tempPrefix() + "huge_count.gltf";
  std::ofstream(path) << doc.dump();
  expectInputError(path, "too large");
}

TEST(Loader, SpotConesOutOfRangeAreClamped) {
  std::ifstream in(data("lights.gltf"));
  nlohmann::json doc = nlohmann::json::parse(in);
  doc["extensions"]["KHR_lights_punctual"]["lights"][1]["spot"] = {{"innerConeAngle", 1.0},
                                                                   {"outerConeAngle", 0.5}};
  std::string path = tempPrefix() + "bad_cone.gltf";
  std::ofstream(path) << doc.dump();
  scene::Scene s = scene::loadScene(path);
  EXPECT_TRUE(hasWarning(s, "clamped"));
  EXPECT_NEAR(s.lights[1].cosOuter, std::cos(0.5f), 1e-6f);
  EXPECT_GT(s.lights[1].cosInner, s.lights[1].cosOuter);
}

TEST(LoaderBadInput, RequiredGeometryCompression) {
  std::ifstream in(data("nonindexed.gltf"));
  nlohmann::json doc = nlohmann::json::parse(in);
  doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  std::string path = tempPrefix() + "draco.gltf";
  std::ofstream(path) << doc.dump();
  expectInputError(path, "KHR_draco_mesh_compression");
}

namespace {

// Every JSON pointer below `at`, for the mutation test.
void collectPointers(const nlohmann::json& j, const nlohmann::json::json_pointer& at,
                     std::vector<nlohmann::json::json_pointer>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.key() == "uri") continue;  // keep the embedded data
      out.push_back(at / it.key());
      collectPointers(it.value(), at / it.key(), out);
    }
  } else if (j.is_array()) {
    for (size_t i = 0; i < j.size(); ++i) {
      out.push_back(at / i);
      collectPointers(j[i], at / i, out);
    }
  }
}

// Loads `path`: either a scene or an InputError; anything else (another exception, a crash)
// fails the test.
void loadOrInputError(const std::string& path, const std::string& what) {
  try {
    scene::loadScene(path);
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << what << ": " << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": " << e.what();
  }
}

}  // namespace

// Random edits of valid files (values replaced by wrong types, out-of-range indices, huge or
// negative numbers; keys removed): the loader answers with a scene or one InputError line.
TEST(LoaderBadInput, RandomMutationsNeverCrash) {
  const char* files[] = {"hierarchy.gltf", "materials.gltf",         "lights.gltf",
                         "cameras.gltf",   "alpha_mask.gltf",        "sparse.gltf",
                         "quantized.gltf", "texture_transform.gltf", "texture16.gltf"};
  const nlohmann::json replacements[] = {-1,
                                         0,
                                         1,
                                         3,
                                         99,
                                         4294967301ll,
                                         -2147483648ll,
                                         1e30,
                                         -0.5,
                                         "x",
                                         nullptr,
                                         nlohmann::json::array(),
                                         nlohmann::json::object(),
                                         {1, 2},
                                         true};
  std::mt19937 rng(2024);
  std::string path = tempPrefix() + "mutated.gltf";
  for (int iteration = 0; iteration < 400; ++iteration) {
    const char* file = files[rng() % std::size(files)];
    std::ifstream in(data(file));
    nlohmann::json doc = nlohmann::json::parse(in);
    std::vector<nlohmann::json::json_pointer> pointers;
    collectPointers(doc, nlohmann::json::json_pointer(), pointers);
    std::string edits;
    for (int e = 1 + int(rng() % 3); e > 0; --e) {
      const auto& p = pointers[rng() % pointers.size()];
      if (!doc.contains(p)) continue;  // under a value an earlier edit replaced
      if (rng() % 5 == 0 && !p.empty()) {
        nlohmann::json& parent = doc[p.parent_pointer()];
        if (parent.is_object()) parent.erase(p.back());
        edits += " erase " + p.to_string();
      } else {
        doc[p] = replacements[rng() % std::size(replacements)];
        edits += " set " + p.to_string() + "=" + doc[p].dump();
      }
    }
    std::ofstream(path) << doc.dump();
    loadOrInputError(path, std::string(file) + edits);
  }
  // Byte flips anywhere in a .glb (header, JSON, binary chunk).
  std::vector<unsigned char> glb = readFile(data("quad.glb"));
  for (int iteration = 0; iteration < 300; ++iteration) {
    std::vector<unsigned char> bytes = glb;
    for (int e = 1 + int(rng() % 6); e > 0; --e) bytes[rng() % bytes.size()] = uint8_t(rng());
    loadOrInputError(tempFile("mutated.glb", bytes), "glb mutation " + std::to_string(iteration));
  }
}

// An image whose header claims more texels than osr-vk reads (a 1024 x 262144 PNG made
// stb_image allocate 1 GiB), and a Radiance .hdr that stb_image would decode forever (it tells
// formats by content, so a .hdr named .png reaches it): refused, naming the image.
TEST(LoaderBadInput, ImagesTooLargeOrThatNeverFinishDecoding) {
  const std::filesystem::path dir = test::tempDir("scene_loader_images");
  std::filesystem::copy_file(data("textured.gltf"), dir / "textured.gltf",
                             std::filesystem::copy_options::overwrite_existing);
  const std::string png = (dir / "checker.png").string();
  std::vector<unsigned char> header = readFile(data("checker.png"));
  ASSERT_GT(header.size(), 24u);
  // IHDR: width and height, big-endian, at bytes 16-23 (stb_image does not check the CRC).
  const unsigned char tall[8] = {0, 0, 4, 0, 0, 4, 0, 0};
  std::copy(tall, tall + 8, header.begin() + 16);
  {
    std::FILE* f = std::fopen(png.c_str(), "wb");
    std::fwrite(header.data(), 1, header.size(), f);
    std::fclose(f);
  }
  expectInputError((dir / "textured.gltf").string(), "image 0: 1024 x 262144 texels, more than osr-vk reads");
  // A run-length scanline whose first count is 0.
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n";
  hdr += std::string("\x02\x02\x00\x08\x00", 5);
  {
    std::FILE* f = std::fopen(png.c_str(), "wb");
    std::fwrite(hdr.data(), 1, hdr.size(), f);
    std::fclose(f);
  }
  expectInputError((dir / "textured.gltf").string(), "image 0: corrupt Radiance .hdr (a run of length 0");
}
