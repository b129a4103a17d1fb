// The first passes of the GPU build against CPU twins: the ordered-float encoding of the
// centroid bounds, bvh_bounds and bvh_morton (bvhMorton, shared with the shader), on sizes that
// hit workgroup tails.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "bvh/bounds.h"
#include "bvh/morton.h"
#include "bvh/synthetic_mesh.h"
#include "bvh_test_util.h"
#include "common/vk_test.h"
#include "vk/buffer_view.h"

using namespace osr;
namespace bb = gpu::bvh_build;

namespace {
float decode(uint32_t o) {
  uint32_t bits = bb::bvhBitsFromOrdered(o);
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}
}  // namespace

TEST(Morton, OrderedFloatEncodingOrdersLikeFloats) {
  std::vector<float> v = {-3e38f, -1.0f, -1e-30f, -0.0f, 0.0f, 1e-30f, 2.5f, 3e38f};
  for (size_t i = 0; i + 1 < v.size(); ++i) {
    uint32_t a, b;
    std::memcpy(&a, &v[i], 4);
    std::memcpy(&b, &v[i + 1], 4);
    EXPECT_LE(bb::bvhOrderedFromBits(a), bb::bvhOrderedFromBits(b)) << v[i] << " " << v[i + 1];
    EXPECT_EQ(decode(bb::bvhOrderedFromBits(a)), v[i]);
  }
}

// Both ways of reaching the large arrays: bindings, and device addresses (scenes past one binding);
// and both ways bvh_bounds reads the scene: its storage arrays, and texel views of them.
TEST(Morton, BoundsAndMortonMatchTheCpuTwin) {
  auto& ctx = test::context();
  for (bool byAddress : {false, true})
  for (bool sceneTexels : {false, true})
  for (uint32_t count : {1u, 63u, 1000u, 5001u}) {
    SCOPED_TRACE(std::string(byAddress ? "by address" : "bindings") + (sceneTexels ? ", scene texels" : ""));
    bvh::SyntheticMesh m = bvh::makeSoup(count, count, {3, -2, 1}, 5.0f, 0.5f, 7);
    vk::Buffer verts = test::deviceBuffer(ctx, m.vertices.size() * 32, "verts", VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
    vk::Buffer tris = test::deviceBuffer(ctx, m.triangles.size() * 16, "tris", VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
    vk::BufferView vertTexels = vk::BufferView::uintTexels(ctx, verts, "vert texels");
    vk::BufferView triTexels = vk::BufferView::uintTexels(ctx, tris, "tri texels");
    verts.uploadVector(m.vertices);
    tris.uploadVector(m.triangles);
    vk::Buffer prims(ctx, count * 48ull, vk::MemoryUse::DeviceLocal, "prims", bvh::BuildTexelViews::kUsage);
    // bvh_morton reads prims through a texel view; it binds but reads no interior or leaf nodes.
    vk::Buffer noNodes(ctx, sizeof(bb::BvhBuildNode), vk::MemoryUse::DeviceLocal, "no nodes", bvh::BuildTexelViews::kUsage);
    vk::BufferView primTexels = vk::BufferView::uintTexels(ctx, prims, "prim texels");
    vk::BufferView noNodeTexels = vk::BufferView::uintTexels(ctx, noNodes, "no node texels");
    bvh::BuildTexelViews texels;
    texels.prims = primTexels.handle();
    texels.interior = texels.leaves = noNodeTexels.handle();
    vk::Buffer info = test::deviceBuffer(ctx, sizeof(bb::BvhBuildInfo), "info");
    vk::Buffer keys = test::deviceBuffer(ctx, count * 4ull, "keys"), values = test::deviceBuffer(ctx, count * 4ull, "values");
    bb::BvhBuildInfo init{};
    float big = 3e38f, small = -3e38f;
    uint32_t bigBits, smallBits;
    std::memcpy(&bigBits, &big, 4);
    std::memcpy(&smallBits, &small, 4);
    init.centroidMin = glm::uvec4(bb::bvhOrderedFromBits(bigBits));
    init.centroidMax = glm::uvec4(bb::bvhOrderedFromBits(smallBits));
    info.upload(&init, sizeof(init));
    bvh::BuildArrayBuffers arrays;
    arrays.triangles = tris;
    arrays.vertices = verts;
    arrays.prims = prims;
    bvh::BoundsPass bounds(ctx, byAddress);
    bvh::MortonPass morton(ctx, byAddress);
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
      bvh::BoundsPass::Args boundsArgs{&arrays, info, count};
      boundsArgs.unusedTexels = primTexels.handle();
      if (sceneTexels) boundsArgs.triangleTexels = triTexels.handle(), boundsArgs.vertexTexels = vertTexels.handle();
      bounds.record(cmd, boundsArgs);
      morton.record(cmd, {&arrays, &texels, info, keys, values, count});
    });
    // CPU twin.
    glm::vec3 lo(big), hi(small);
    std::vector<glm::vec3> centroids;
    for (const auto& t : m.triangles) {
      glm::vec3 p0 = m.vertices[t.v0].position, p1 = m.vertices[t.v1].position, p2 = m.vertices[t.v2].position;
      glm::vec3 c = 0.5f * (glm::min(glm::min(p0, p1), p2) + glm::max(glm::max(p0, p1), p2));
      centroids.push_back(c);
      lo = glm::min(lo, c);
      hi = glm::max(hi, c);
    }
    auto got = info.downloadVector<bb::BvhBuildInfo>(1)[0];
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(decode(got.centroidMin[k]), lo[k]) << count;
      EXPECT_EQ(decode(got.centroidMax[k]), hi[k]) << count;
    }
    auto gotKeys = keys.downloadVector<uint32_t>(count);
    auto gotValues = values.downloadVector<uint32_t>(count);
    glm::vec3 ext = hi - lo;
    glm::vec3 scale(ext.x > 0 ? 1 / ext.x : 0, ext.y > 0 ? 1 / ext.y : 0, ext.z > 0 ? 1 / ext.z : 0);
    uint32_t mismatches = 0;
    for (uint32_t i = 0; i < count; ++i) {
      glm::vec3 u = (centroids[i] - lo) * scale;
      EXPECT_EQ(gotValues[i], i);
      mismatches += gotKeys[i] != bb::bvhMorton(u.x, u.y, u.z);
    }
    EXPECT_EQ(mismatches, 0u) << count;
  }
}
