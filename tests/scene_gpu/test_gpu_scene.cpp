// GpuScene: the device buffers hold exactly the loaded scene, padded where empty, and a scene
// past maxStorageBufferRange is refused with a message naming the limit.
#include <gtest/gtest.h>

#include <cstring>

#include "common/error.h"
#include "common/vk_test.h"
#include "scene_gpu/gpu_scene.h"

using namespace osr;
namespace gs = osr::gpu::scene;

// std430 layout of the shared structs (the GLSL side is checked by test_scene_probe).
static_assert(sizeof(gs::Vertex) == 32 && offsetof(gs::Vertex, normal) == 16);
static_assert(sizeof(gs::Triangle) == 16);
static_assert(sizeof(gs::Material) == 240);
static_assert(offsetof(gs::Material, emission) == 16 &&
              offsetof(gs::Material, specularColor) == 32);
static_assert(offsetof(gs::Material, baseColorTexture) == 64 &&
              offsetof(gs::Material, flags) == 92);
static_assert(sizeof(gs::TextureInfo) == 16 && sizeof(gs::EmissiveTriangle) == 16);
static_assert(sizeof(gs::PunctualLight) == 64 && offsetof(gs::PunctualLight, intensity) == 32);
static_assert(sizeof(gs::SceneInfo) == 64 && offsetof(gs::SceneInfo, boundsMin) == 32);

TEST(GpuScene, UploadsTheCornellBox) {
  auto& ctx = test::context();
  scene::Scene s = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  scene::GpuScene g(ctx, s);
  EXPECT_EQ(g.triangleCount, s.triangles.size());
  auto tris = g.triangles.downloadVector<gs::Triangle>(s.triangles.size());
  EXPECT_EQ(std::memcmp(tris.data(), s.triangles.data(), tris.size() * sizeof(gs::Triangle)), 0);
  auto verts = g.vertices.downloadVector<gs::Vertex>(s.vertices.size());
  EXPECT_EQ(std::memcmp(verts.data(), s.vertices.data(), verts.size() * sizeof(gs::Vertex)), 0);
  auto info = g.info.downloadVector<gs::SceneInfo>(1)[0];
  EXPECT_EQ(info.triangleCount, s.triangles.size());
  EXPECT_EQ(info.emissiveCount, s.emissive.size());
  EXPECT_EQ(info.lightCount, 0u);
  EXPECT_EQ(info.envWidth, 0u);
  EXPECT_EQ(glm::vec3(info.boundsMin), s.boundsMin);
  // Empty lists are padded to one element so every binding is valid.
  EXPECT_EQ(g.lights.size(), sizeof(gs::PunctualLight));
  EXPECT_EQ(g.texels.size(), 4u);
  EXPECT_EQ(g.bindings().size(), gs::kSceneBindingCount);
  EXPECT_EQ(g.bindings()[gs::kSceneBindingTriangles].buffer, &g.triangles);
}

// features names exactly what the scene uses (passes compile the rest out).
TEST(GpuScene, FeaturesNameWhatTheSceneUses) {
  auto& ctx = test::context();
  scene::Scene s = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  EXPECT_EQ(scene::GpuScene(ctx, s).features, 0u);  // no alpha, texture, light or map
  s.materials[0].iridescence = 0.5f;  // a thin film alone is a layer
  EXPECT_EQ(scene::GpuScene(ctx, s).features, gs::kSceneFeatureLayers);
  s.materials[0].iridescence = 0.0f;
  s.materials[0].flags |= gs::kMaterialAlphaBlend;
  EXPECT_EQ(scene::GpuScene(ctx, s).features,
            gs::kSceneFeatureAlphaTest | gs::kSceneFeatureAlphaBlend);
  s.materials[0].flags &= ~gs::kMaterialAlphaBlend;
  s.materials[0].flags |= gs::kMaterialAlphaMask;
  s.materials[1].transmission = 0.5f;
  s.materials[1].clearcoat = 1.0f;
  s.textures.push_back({});
  s.textures.back().width = s.textures.back().height = 1;
  s.textures.back().texels = {0xffffffffu};
  s.materials[2].flags |= gs::kMaterialAlphaBlend;
  s.attributes.resize(s.vertices.size());
  s.lights.push_back({});
  scene::Environment env;
  env.width = 2;
  env.height = 1;
  env.texels = {glm::vec4(1.0f), glm::vec4(1.0f)};
  EXPECT_EQ(scene::GpuScene(ctx, s, &env).features, gs::kSceneFeatureAll);
}

// Texel views exist for every pass that binds them; texel reads are on where they cover the
// buffers (the renderer tests check the images pt_trace computes through them).
TEST(GpuScene, TexelViewsCoverVerticesTrianglesMaterials) {
  auto& ctx = test::context();
  scene::GpuScene g(ctx, scene::loadScene(test::referencePath("cornell/cornell.gltf")));
  for (VkBufferView v : g.texelViews()) EXPECT_NE(v, VkBufferView(VK_NULL_HANDLE));
  uint64_t maxTexels = ctx.caps().maxTexelBufferElements;
  EXPECT_EQ(g.texelFetch, g.vertices.size() / 16 <= maxTexels && g.materials.size() / 16 <= maxTexels);
  EXPECT_EQ(g.vertices.size() % 16, 0u);
  EXPECT_EQ(g.materials.size() % 16, 0u);
}

// A buffer a shader could not read whole is refused in one line naming the scene, the buffer,
// its size and the device limit.
void expectRefused(const vk::Context& ctx, const scene::Scene& s, const char* what, const char* limitName) {
  try {
    scene::GpuScene g(ctx, s);
    ADD_FAILURE() << what << ": expected a DeviceError";
  } catch (const DeviceError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find(limitName), std::string::npos) << msg;
    EXPECT_NE(msg.find(" MiB ("), std::string::npos) << msg;
    EXPECT_NE(msg.find("cornell.gltf"), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(GpuScene, RefusesBuffersPastMaxStorageBufferRange) {
  auto& ctx = test::context();
  uint64_t limit = ctx.caps().maxStorageBufferRange;
  if (limit > (512ull << 20)) GTEST_SKIP() << "device allows " << (limit >> 20) << " MiB buffers";
  const scene::Scene base = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  scene::Scene s = base;
  scene::Texture big;
  big.width = 4096;
  big.height = uint32_t(limit / 4 / 4096 + 1);
  big.texels.resize(size_t(big.width) * big.height);
  s.textures.push_back(std::move(big));
  expectRefused(ctx, s, "textures", "maxStorageBufferRange");
}

// Vertices, triangles and materials are read by texel fetch where texel views reach further than
// storage bindings (lavapipe: 2 GiB, its allocation limit): past maxStorageBufferRange they load,
// and the allocation limit refuses them, tested here with a device whose limit is lowered to 64 MiB.
TEST(GpuScene, TexelReadBuffersReachTheAllocationLimit) {
  auto& ctx = test::context();
  const auto& caps = ctx.caps();
  if (uint64_t(caps.maxTexelBufferElements) * 16 <= caps.maxStorageBufferRange)
    GTEST_SKIP() << "texel views reach no further than storage bindings here";
  scene::Scene s = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  s.vertices.resize(caps.maxStorageBufferRange / sizeof(gs::Vertex) + 1);
  {
    scene::GpuScene g(ctx, s);
    EXPECT_TRUE(g.texelFetch);
    EXPECT_EQ(g.vertices.size(), s.vertices.size() * sizeof(gs::Vertex));
    // The storage slot, which shading does not read here, holds what a binding can.
    EXPECT_LE(g.bindings()[gs::kSceneBindingVertices].bytes(), caps.maxStorageBufferRange);
  }
  vk::ContextOptions options;
  options.validation = true;
  options.testMaxAllocationBytes = 64ull << 20;
  vk::Context small(options);
  s.vertices.resize((64ull << 20) / sizeof(gs::Vertex) + 1);
  expectRefused(small, s, "vertex", "maxMemoryAllocationSize");
  EXPECT_EQ(small.validationMessages(), 0u);
}
