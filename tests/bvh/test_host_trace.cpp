// HostTracer (the CPU twin of bvhClosestHit used to verify benchmarks) against the brute-force
// loop on every test mesh.
#include <gtest/gtest.h>

#include "bvh/host_trace.h"
#include "bvh_test_util.h"

using namespace osr;

TEST(HostTrace, MatchesBruteForce) {
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::HostBvh tree = bvh::buildCpu(mesh.vertices, mesh.triangles);
    auto leaves = bvh::makeLeafTriangles(tree, mesh.vertices, mesh.triangles);
    bvh::HostTracer tracer(tree, leaves);
    auto rays = test::randomRays(mesh, 20000, 41);
    std::vector<test::TraceHit> hits;
    for (const auto& r : rays) hits.push_back(tracer.closest(r));
    EXPECT_EQ(test::compareClosest(name, mesh, rays, hits), 0u) << name;
  }
}
