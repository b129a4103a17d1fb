// bvh.h: buildOnHost (download, CPU build, upload) gives a valid device tree that traces like
// the brute-force loop; maxTriangles follows maxStorageBufferRange.
#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/tree_stats.h"
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
  uint64_t n = bvh::maxTriangles(ctx);
  EXPECT_GT(n, 1000000u);  // the 1M-triangle benchmark mesh fits on lavapipe's 128 MiB
  EXPECT_LE(n * sizeof(gpu::bvh::BvhNode), ctx.caps().maxStorageBufferRange);
  EXPECT_LE(n * sizeof(gpu::bvh::BvhLeafTriangle), ctx.caps().maxStorageBufferRange);
}
