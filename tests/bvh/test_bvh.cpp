// bvh.h: buildOnHost (download, CPU build, upload) gives a valid device tree that traces like
// the brute-force loop; maxTriangles follows maxStorageBufferRange.
#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/tree_stats.h"
#include "shaders/shared/bvh_build.h"
#include "bvh_test_util.h"
#include "common/vk_test.h"
#include "trace_test_util.h"

using namespace osr;

TEST(Bvh, BuildOnHostRoundTrips) {
  auto& ctx = test::context();
  bvh::SyntheticMesh mesh = bvh::makeSphere({0, 0, 0}, 1.0f, 24, 12, 0.2f);
  vk::Buffer vertices(ctx, mesh.vertices.size() * 32, vk::MemoryUse::DeviceLocal, "vertices");
  vk::Buffer triangles(ctx, mesh.triangles.size() * 16, vk::MemoryUse::DeviceLocal, "triangles");
  vertices.uploadVector(mesh.vertices);
  triangles.uploadVector(mesh.triangles);
  bvh::BuildStats stats;
  bvh::Bvh tree = bvh::buildOnHost(ctx, vertices, triangles, uint32_t(mesh.triangles.size()), &stats);
  bvh::HostBvh host = bvh::download(tree);
  EXPECT_EQ(bvh::checkInvariants(host, mesh.vertices, mesh.triangles), "");
  EXPECT_NEAR(stats.sahCost, bvh::sahCost(host), 1e-9);
  EXPECT_EQ(stats.depth, bvh::depth(host));
  auto rays = test::randomRays(mesh, 20000, 51);
  auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
  EXPECT_EQ(test::compareClosest("buildOnHost", mesh, rays, hits), 0u);
}

TEST(Bvh, MaxTrianglesFitsEveryBinding) {
  auto& ctx = test::context();
  const auto& caps = ctx.caps();
  uint64_t n = bvh::maxTriangles(ctx);
  // Scale (issue 13): 10M triangles fit lavapipe (128 MiB bindings, 2 GiB allocations).
  EXPECT_GE(n, 10000000u);
  // Each BVH array is one allocation...
  EXPECT_LE((n - 1) * sizeof(gpu::bvh::BvhNode), caps.maxMemoryAllocationSize);
  EXPECT_LE(n * sizeof(gpu::bvh_build::BvhBuildNode), caps.maxMemoryAllocationSize);
  // ...that traversal reads through one binding of the kind it uses...
  uint64_t readable = bvh::texelFetchCovers(ctx) ? uint64_t(caps.maxTexelBufferElements) * 16 : caps.maxStorageBufferRange;
  EXPECT_LE((n - 1) * sizeof(gpu::bvh::BvhNode), readable);
  EXPECT_LE(n * sizeof(gpu::bvh::BvhLeafTriangle), readable);
  // ...and the build's sort keys are storage bindings.
  EXPECT_LE(n * 4, caps.maxStorageBufferRange);
}
