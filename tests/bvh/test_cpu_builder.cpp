// CPU binned-SAH builder: structural invariants on every test mesh, the depth bound on a mesh
// built to make SAH splits peel one triangle at a time, SAH quality against a median split.
#include <gtest/gtest.h>

#include "bvh/cpu_builder.h"
#include "bvh/tree_stats.h"
#include "bvh_test_util.h"
#include "common/error.h"

using namespace osr;

TEST(CpuBuilder, InvariantsHoldOnEveryTestMesh) {
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::HostBvh tree = bvh::buildCpu(mesh.vertices, mesh.triangles);
    EXPECT_EQ(bvh::checkInvariants(tree, mesh.vertices, mesh.triangles), "") << name;
    EXPECT_EQ(tree.leafTriangles.size(), mesh.triangles.size()) << name;
    EXPECT_LE(bvh::depth(tree), gpu::bvh::kBvhMaxDepth) << name;
    EXPECT_GT(bvh::sahCost(tree), 0.0) << name;
  }
}

TEST(CpuBuilder, DepthStaysBoundedOnGeometricallySpacedTriangles) {
  // Triangles at x = 1.4^i: the SAH cut that isolates the largest one is always best, which
  // without the depth guard gives a path as long as the triangle count.
  bvh::SyntheticMesh m;
  for (uint32_t i = 0; i < 300; ++i) {
    float x = std::pow(1.4f, float(i % 150)) * (i < 150 ? 1.0f : -1.0f);
    float s = std::abs(x) * 0.01f;
    uint32_t base = uint32_t(m.vertices.size());
    for (glm::vec3 p : {glm::vec3(x, 0, 0), glm::vec3(x + s, s, 0), glm::vec3(x, s, s)}) {
      gpu::scene::Vertex v{};
      v.position = p;
      m.vertices.push_back(v);
    }
    m.triangles.push_back({base, base + 1, base + 2, 0});
  }
  bvh::HostBvh tree = bvh::buildCpu(m.vertices, m.triangles);
  EXPECT_EQ(bvh::checkInvariants(tree, m.vertices, m.triangles), "");
  EXPECT_LE(bvh::depth(tree), gpu::bvh::kBvhMaxDepth);
  EXPECT_GT(bvh::depth(tree), 20u);  // the mesh really is pathological
}

TEST(CpuBuilder, SahBeatsATwoBinBuild) {
  // With 2 bins the builder degenerates to spatial-median splits; full binning must do better.
  auto meshes = test::testMeshes();
  const auto& mesh = meshes[0].mesh;
  double full = bvh::sahCost(bvh::buildCpu(mesh.vertices, mesh.triangles));
  bvh::CpuBuildOptions coarse;
  coarse.bins = 2;
  double median = bvh::sahCost(bvh::buildCpu(mesh.vertices, mesh.triangles, coarse));
  EXPECT_LT(full, median);
}

TEST(CpuBuilder, SahOfAHandBuiltTreeMatchesTheFormula) {
  // Two unit squares' worth of triangles far apart: root node + two one-triangle leaves.
  bvh::SyntheticMesh m;
  for (float x : {0.0f, 9.0f}) {
    uint32_t base = uint32_t(m.vertices.size());
    for (glm::vec3 p : {glm::vec3(x, 0, 0), glm::vec3(x + 1, 0, 0), glm::vec3(x, 1, 1)}) {
      gpu::scene::Vertex v{};
      v.position = p;
      m.vertices.push_back(v);
    }
    m.triangles.push_back({base, base + 1, base + 2, 0});
  }
  bvh::HostBvh tree = bvh::buildCpu(m.vertices, m.triangles);
  ASSERT_EQ(tree.nodes.size(), 1u);
  // Root box 10x1x1: area 2*(10+1+10) = 42; each leaf box 1x1x1: area 6.
  double expected = (gpu::bvh::kSahNodeCost * 42.0 + 2 * gpu::bvh::kSahTriangleCost * 6.0) / 42.0;
  EXPECT_NEAR(bvh::sahCost(tree), expected, 1e-6);
}

TEST(CpuBuilder, RefusesBadInput) {
  bvh::SyntheticMesh m = bvh::makeSoup(4, 1, {0, 0, 0}, 1, 1);
  EXPECT_THROW(bvh::buildCpu(m.vertices, {}), InputError);
  m.triangles[2].v1 = 99;
  EXPECT_THROW(bvh::buildCpu(m.vertices, m.triangles), InputError);
}
