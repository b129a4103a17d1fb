// tree_stats: the invariant checker must catch each kind of broken tree (so that the builder
// tests relying on it can fail), and depth/SAH must follow their definitions.
#include <gtest/gtest.h>

#include "bvh/cpu_builder.h"
#include "bvh/tree_stats.h"
#include "bvh_test_util.h"

using namespace osr;

namespace {
struct Fixture {
  bvh::SyntheticMesh mesh = bvh::makeSoup(500, 17, {0, 0, 0}, 1.0f, 0.1f);
  bvh::HostBvh tree = bvh::buildCpu(mesh.vertices, mesh.triangles);
  std::string check() const { return bvh::checkInvariants(tree, mesh.vertices, mesh.triangles); }
};
}  // namespace

TEST(TreeStats, ValidTreePasses) { EXPECT_EQ(Fixture().check(), ""); }

TEST(TreeStats, ShrunkenChildBoxIsCaught) {
  Fixture f;
  f.tree.nodes[0].aMax = f.tree.nodes[0].aMin;  // a child box no longer holds its subtree
  EXPECT_NE(f.check().find("inside"), std::string::npos) << f.check();
}

TEST(TreeStats, TriangleInTwoLeavesIsCaught) {
  Fixture f;
  f.tree.leafTriangles[1] = f.tree.leafTriangles[0];
  EXPECT_NE(f.check(), "");
}

TEST(TreeStats, CycleIsCaught) {
  Fixture f;
  ASSERT_GT(f.tree.nodes.size(), 2u);
  // Point some interior child back at the root.
  for (auto& n : f.tree.nodes)
    if (!(n.a & gpu::bvh::kBvhLeafFlag)) {
      n.a = 0;
      break;
    }
  EXPECT_NE(f.check(), "");
}

TEST(TreeStats, DepthPastTheTraversalBoundIsCaught) {
  // A chain: node i has one leaf (triangle i) and node i+1 as children.
  const uint32_t n = gpu::bvh::kBvhMaxDepth + 2;
  bvh::SyntheticMesh mesh = bvh::makeSoup(n + 1, 3, {0, 0, 0}, 0.0f, 1.0f);
  bvh::HostBvh tree;
  for (uint32_t i = 0; i < n; ++i) {
    gpu::bvh::BvhNode node{};
    node.aMin = node.bMin = glm::vec3(-10);
    node.aMax = node.bMax = glm::vec3(10);
    node.a = gpu::bvh::kBvhLeafFlag | (1u << gpu::bvh::kBvhLeafCountShift) | i;
    tree.leafTriangles.push_back(i);
    node.b = i + 1 < n ? i + 1 : (gpu::bvh::kBvhLeafFlag | (1u << gpu::bvh::kBvhLeafCountShift) | n);
    tree.nodes.push_back(node);
  }
  tree.leafTriangles.push_back(n);
  EXPECT_EQ(bvh::depth(tree), n);
  EXPECT_NE(bvh::checkInvariants(tree, mesh.vertices, mesh.triangles).find("kBvhMaxDepth"), std::string::npos);
}

TEST(TreeStats, LeafPairOutOfOrderIsCaught) {
  // Two leaf children whose entries are not consecutive (b before a): traversal would intersect
  // the wrong range.
  Fixture f;
  using gpu::bvh::kBvhLeafFlag;
  for (auto& n : f.tree.nodes)
    if ((n.a & kBvhLeafFlag) && (n.b & kBvhLeafFlag) && ((n.a >> gpu::bvh::kBvhLeafCountShift) & gpu::bvh::kBvhLeafCountMask)) {
      std::swap(n.a, n.b);
      std::swap(n.aMin, n.bMin);
      std::swap(n.aMax, n.bMax);
      EXPECT_NE(f.check().find("does not follow"), std::string::npos) << f.check();
      return;
    }
  FAIL() << "no node with two leaf children";
}
