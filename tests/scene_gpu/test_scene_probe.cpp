// scene_probe.comp (lib/scene.glsl: surfaceAt, sampleTexture, osrAlphaCutout) against the C++
// twins of src/scene/surface.cpp, at random hit records on scenes covering every texture slot,
// wrap mode, normal mapping, alpha modes, node transforms and the reference scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/vk_test.h"
#include "scene/environment.h"
#include "scene/scene_test_util.h"
#include "support/scene_probe.h"
#include "scene/surface.h"

using namespace osr;
namespace probe = osr::gpu::scene_probe;
namespace envp = osr::gpu::scene_env_probe;
constexpr float kPi = 3.14159265358979f;

static_assert(sizeof(probe::Query) == 16);
static_assert(sizeof(probe::Result) == 128 && offsetof(probe::Result, uv) == 96 &&
              offsetof(probe::Result, geometricNormal) == 16);

namespace {

struct Case {
  const char* name;
  std::string path;
};

void checkScene(const scene::Scene& s, uint32_t count) {
  const std::string& path = s.path;
  auto& ctx = test::context();
  scene::GpuScene g(ctx, s);
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::vector<probe::Query> queries(count);
  for (uint32_t i = 0; i < count; ++i) {
    float b1 = u01(rng), b2 = u01(rng);
    if (b1 + b2 > 1.0f) {
      b1 = 1.0f - b1;
      b2 = 1.0f - b2;
    }
    // Every triangle at least once, then random ones; a few exact corners.
    uint32_t tri = i < s.triangles.size() ? i : uint32_t(rng() % s.triangles.size());
    if (i % 17 == 0) b1 = b2 = 0.0f;
    queries[i] = {tri, b1, b2, 0};
  }
  vk::Buffer q(ctx, queries.size() * sizeof(probe::Query), vk::MemoryUse::DeviceLocal, "queries");
  vk::Buffer r(ctx, queries.size() * sizeof(probe::Result), vk::MemoryUse::DeviceLocal, "results");
  q.uploadVector(queries);
  scene::SceneProbe pass(ctx, scene::ProbeKind::Surface);
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, {&q, &r, count, &g}); });
  auto results = r.downloadVector<probe::Result>(count);

  float scale = glm::length(s.boundsMax - s.boundsMin) + 1.0f;
  int cutouts = 0;
  for (uint32_t i = 0; i < count; ++i) {
    const probe::Query& qu = queries[i];
    const probe::Result& gpu = results[i];
    scene::SurfaceSample cpu = scene::surfaceAt(s, qu.triangle, {qu.b1, qu.b2});
    bool cpuCut = scene::alphaCutout(s, qu.triangle, {qu.b1, qu.b2}, probe::kProbeRayOrigin,
                                     probe::kProbeRayInvDir);
    std::string where = path + " query " + std::to_string(i) + " triangle " +
                        std::to_string(qu.triangle) + " b=(" + std::to_string(qu.b1) + ", " +
                        std::to_string(qu.b2) + ")";
    auto near3 = [&](glm::vec3 a, glm::vec3 b, float tol, const char* what) {
      EXPECT_LE(glm::length(a - b), tol)
          << where << " " << what << ": gpu (" << a.x << ", " << a.y << ", " << a.z << ") cpu ("
          << b.x << ", " << b.y << ", " << b.z << ")";
    };
    near3(gpu.position, cpu.position, 1e-5f * scale, "position");
    near3(gpu.geometricNormal, cpu.geometricNormal, 1e-4f, "geometric normal");
    near3(gpu.shadingNormal, cpu.shadingNormal, 2e-4f, "shading normal");
    near3(gpu.baseColor, cpu.m.baseColor, 1e-4f, "base color");
    near3(gpu.emission, cpu.m.emission, 1e-4f * (1.0f + glm::length(cpu.m.emission)), "emission");
    near3(gpu.specularColor, cpu.m.specularColor, 1e-4f, "specular color");
    glm::vec2 uv0(cpu.uv);
    EXPECT_LE(glm::length(gpu.uv - uv0), 1e-5f * (1.0f + glm::length(uv0))) << where << " uv";
    EXPECT_EQ(gpu.material, cpu.material) << where;
    EXPECT_NEAR(gpu.alpha, cpu.m.alpha, 1e-4f) << where;
    EXPECT_NEAR(gpu.metallic, cpu.m.metallic, 1e-4f) << where;
    EXPECT_NEAR(gpu.roughness, cpu.m.roughness, 1e-4f) << where;
    EXPECT_NEAR(gpu.specular, cpu.m.specular, 1e-4f) << where;
    EXPECT_NEAR(gpu.ior, cpu.m.ior, 1e-6f) << where;
    EXPECT_NEAR(gpu.transmission, cpu.m.transmission, 1e-4f) << where;
    EXPECT_EQ(gpu.doubleSided != 0, cpu.m.doubleSided) << where;
    const auto& mat = s.materials[cpu.material];
    if (std::abs(cpu.m.alpha - mat.alphaCutoff) > 1e-3f) {
      EXPECT_EQ(gpu.alphaCutout != 0, cpuCut) << where << " alpha " << cpu.m.alpha;
    }
    cutouts += cpuCut;
  }
  if (path.find("alpha_mask") != std::string::npos) {
    // Both outcomes occur: the test can tell a cut from a hit.
    EXPECT_GT(cutouts, int(count / 10));
    EXPECT_LT(cutouts, int(count * 9 / 10));
  }
}

void checkScene(const std::string& path, uint32_t count) {
  checkScene(scene::loadScene(path), count);
}

}  // namespace

// Negative and far-out uvs (thousands of periods) under each wrap mode and filter: the GLSL wrap
// must not rely on `%` of negative numbers (undefined in GLSL) and must agree with the C++ twin.
TEST(SceneProbe, FarUvsUnderEveryWrapMode) {
  scene::Scene s;
  s.path = "far uvs (in memory)";
  for (uint32_t mode = 0; mode < 18; ++mode) {  // 3 x 3 wrap modes, bilinear and nearest
    scene::Texture t;
    t.width = 5;
    t.height = 3;
    t.wrap = (mode % 3) | (((mode / 3) % 3) << 2) | (mode >= 9 ? gpu::scene::kTextureNearest : 0u);
    for (uint32_t i = 0; i < 15; ++i)
      t.texels.push_back(0xff000000u | (i * 17u) | ((255u - i * 13u) << 8));
    s.textures.push_back(t);
    gpu::scene::Material m = scene::defaultMaterial();
    m.baseColorTexture = int(mode);
    s.materials.push_back(m);
    float o = -3000.0f + 350.0f * mode;
    uint32_t v = uint32_t(s.vertices.size());
    s.vertices.push_back({{0, 0, 0}, o, {0, 0, 1}, -o});
    s.vertices.push_back({{1, 0, 0}, o + 7.3f, {0, 0, 1}, -o});
    s.vertices.push_back({{0, 1, 0}, o, {0, 0, 1}, -o - 5.1f});
    s.triangles.push_back({v, v + 1, v + 2, mode});
  }
  checkScene(s, 3000);
}

TEST(SceneProbe, TexturedAllSlotsWrapModesAndNormalMap) {
  checkScene(test::dataPath("scene/textured.gltf"), 2000);
}
TEST(SceneProbe, AlphaMask) {
  checkScene(test::dataPath("scene/alpha_mask.gltf"), 2000);
}
TEST(SceneProbe, HierarchyAndMaterials) {
  checkScene(test::dataPath("scene/hierarchy.gltf"), 500);
  checkScene(test::dataPath("scene/materials.gltf"), 500);
  checkScene(test::dataPath("scene/quad.glb"), 200);
  checkScene(test::dataPath("scene/degenerate_attributes.gltf"), 200);
  checkScene(test::dataPath("scene/texture16.gltf"), 200);
  checkScene(test::dataPath("scene/texture_transform.gltf"), 200);
  checkScene(test::dataPath("scene/vertex_attributes.gltf"), 500);
}
TEST(SceneProbe, ReferenceScenes) {
  checkScene(test::referencePath("cornell/cornell.gltf"), 1000);
  checkScene(test::referencePath("room/room.gltf"), 5000);
}

TEST(SceneProbe, EnvironmentMatchesCpu) {
  auto& ctx = test::context();
  scene::Scene s = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  scene::Environment env = test::testEnvironment();
  std::vector<float> cdf = scene::environmentCdf(env);
  scene::GpuScene g(ctx, s, &env);
  auto info = g.info.downloadVector<osr::gpu::scene::SceneInfo>(1)[0];
  EXPECT_EQ(info.envWidth, 16u);
  EXPECT_EQ(info.envHeight, 8u);
  EXPECT_EQ(g.environmentCdf.downloadVector<float>(cdf.size()), cdf);
  const uint32_t n = 3000;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::vector<envp::Query> queries(n);
  for (auto& q : queries) {
    float z = 1.0f - 2.0f * u01(rng), phi = 2.0f * kPi * u01(rng),
          r = std::sqrt(std::max(0.0f, 1 - z * z));
    q.direction = {r * std::cos(phi), z, r * std::sin(phi)};
    q.u = {u01(rng), u01(rng)};
  }
  vk::Buffer qb(ctx, n * sizeof(envp::Query), vk::MemoryUse::DeviceLocal, "env queries");
  vk::Buffer rb(ctx, n * sizeof(envp::Result), vk::MemoryUse::DeviceLocal, "env results");
  qb.uploadVector(queries);
  scene::SceneProbe pass(ctx, scene::ProbeKind::Environment);
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, {&qb, &rb, n, &g}); });
  auto results = rb.downloadVector<envp::Result>(n);
  int mismatchedTexel = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const auto& q = queries[i];
    const auto& r = results[i];
    glm::vec3 radiance = scene::environmentRadiance(env, q.direction);
    float pdf = scene::environmentPdf(env, cdf, q.direction);
    // A direction on a texel border may land on either side in float: allow a few.
    if (glm::length(r.radiance - radiance) > 1e-5f || std::abs(r.pdf - pdf) > 1e-3f * pdf) {
      ++mismatchedTexel;
      continue;
    }
    float spdf;
    glm::vec3 srad;
    glm::vec3 sdir = scene::sampleEnvironment(env, cdf, q.u, spdf, srad);
    EXPECT_LE(glm::length(r.sampledDirection - sdir), 1e-4f) << "query " << i;
    EXPECT_NEAR(r.sampledPdf, spdf, 1e-3f * spdf) << "query " << i;
    EXPECT_EQ(r.sampledRadiance, srad) << "query " << i;
  }
  EXPECT_LE(mismatchedTexel, 3);
  // No environment: black, pdf 0.
  scene::GpuScene none(ctx, s);
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, {&qb, &rb, n, &none}); });
  results = rb.downloadVector<envp::Result>(n);
  EXPECT_EQ(results[0].radiance, glm::vec3(0.0f));
  EXPECT_EQ(results[0].pdf, 0.0f);
  EXPECT_EQ(results[0].sampledPdf, 0.0f);
}
