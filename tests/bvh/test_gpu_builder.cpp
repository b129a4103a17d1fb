// buildGpu end to end (LBVH + treelets, and PLOC): structural invariants of the downloaded tree
// on every test mesh, SAH within 1.1x of the CPU binned-SAH tree, treelet restructuring lowering
// the LBVH's SAH, reported statistics matching the downloaded tree, closest hits equal to the
// brute-force loop, and a clear refusal past the device limit.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "bvh/cpu_builder.h"
#include "bvh/gpu_builder.h"
#include "bvh/host_trace.h"
#include "bvh/node_quantize.h"
#include "bvh/ploc.h"
#include "bvh/tree_stats.h"
#include "bvh_test_util.h"
#include "common/error.h"
#include "common/vk_test.h"
#include "scene/scene.h"
#include "trace_test_util.h"

using namespace osr;

namespace {

struct DeviceMesh {
  vk::Buffer vertices, triangles;
  DeviceMesh(const vk::Context& ctx, const bvh::SyntheticMesh& m)
      : vertices(ctx, m.vertices.size() * sizeof(gpu::scene::Vertex), vk::MemoryUse::DeviceLocal, "test vertices"),
        triangles(ctx, m.triangles.size() * sizeof(gpu::scene::Triangle), vk::MemoryUse::DeviceLocal, "test triangles") {
    vertices.uploadVector(m.vertices);
    triangles.uploadVector(m.triangles);
  }
};

}  // namespace

// Compiles the build's pipelines once for the suite and frees them before the context goes.
class GpuBuilder : public ::testing::Test {
 protected:
  static void TearDownTestSuite() { builder_.reset(); }
  // Both node forms by default: the checks read the exact nodes and compare the quantized ones.
  static bvh::Bvh build(const bvh::SyntheticMesh& m, bvh::BuildStats* stats = nullptr,
                        bvh::NodeForms forms = bvh::NodeForms::Both) {
    auto& ctx = test::context();
    if (!builder_) builder_ = std::make_unique<bvh::GpuBuilder>(ctx);
    DeviceMesh dm(ctx, m);
    return builder_->build(dm.vertices, dm.triangles, uint32_t(m.triangles.size()), stats, forms);
  }
  static std::unique_ptr<bvh::GpuBuilder> builder_;
};
std::unique_ptr<bvh::GpuBuilder> GpuBuilder::builder_;

TEST_F(GpuBuilder, InvariantsHoldOnEveryTestMesh) {
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::BuildStats stats;
    bvh::Bvh tree = build(mesh, &stats);
    bvh::HostBvh host = bvh::download(tree);
    EXPECT_EQ(bvh::checkInvariants(host, mesh.vertices, mesh.triangles), "") << name;
    EXPECT_EQ(stats.depth, bvh::depth(host)) << name;
    EXPECT_NEAR(stats.sahCost, bvh::sahCost(host), 1e-3 * bvh::sahCost(host)) << name;
    EXPECT_FALSE(stats.passes.empty()) << name;
  }
}

// Traversal nodes are stored depth-first (child a right after its parent, b after a's subtree, all
// of them in [0, count)), and the quantized copy is the host's quantization of the exact nodes.
TEST_F(GpuBuilder, NodesAreDepthFirstAndQuantizedAsOnTheHost) {
  auto meshes = test::testMeshes();
  meshes.push_back({"bumpy_sphere_20k", bvh::makeSphere({0, 0, 0}, 1.0f, 200, 50, 0.3f)});
  for (const auto& [name, mesh] : meshes) {
    bvh::Bvh tree = build(mesh);
    auto nodes = tree.nodes.downloadVector<gpu::bvh::BvhNode>(tree.nodeCount);
    auto quantized = tree.traversalNodes.downloadVector<gpu::bvh::BvhTraversalNode>(tree.nodeCount);
    // Walk depth-first, a before b: the k-th node visited must sit at index k.
    std::vector<uint32_t> stack = {0};
    uint32_t visited = 0, misplaced = 0, differ = 0;
    while (!stack.empty()) {
      uint32_t i = stack.back();
      stack.pop_back();
      misplaced += i != visited++;
      const gpu::bvh::BvhTraversalNode expected = bvh::quantizeNode(nodes[i]);
      differ += expected.frame != quantized[i].frame || expected.boxes != quantized[i].boxes;
      if (!(nodes[i].b & gpu::bvh::kBvhLeafFlag)) stack.push_back(nodes[i].b);
      if (!(nodes[i].a & gpu::bvh::kBvhLeafFlag)) stack.push_back(nodes[i].a);
      if (visited > tree.nodeCount) break;  // a cycle: reported below
    }
    EXPECT_LE(visited, tree.nodeCount) << name;
    EXPECT_EQ(misplaced, 0u) << name << ": of " << visited << " nodes";
    EXPECT_EQ(differ, 0u) << name << ": of " << visited << " nodes";
  }
}

namespace {

// The written nodes of a tree with exact nodes: [0, the number reachable from the root), in
// depth-first order; past nodeCount where the links loop.
uint32_t liveNodes(const bvh::Bvh& tree) {
  const auto nodes = tree.nodes.downloadVector<gpu::bvh::BvhNode>(tree.nodeCount);
  uint32_t live = 0;
  for (std::vector<uint32_t> stack = {0}; !stack.empty() && live <= tree.nodeCount; ++live) {
    const gpu::bvh::BvhNode& n = nodes[stack.back()];
    stack.pop_back();
    for (uint32_t ref : {n.a, n.b})
      if (!(ref & gpu::bvh::kBvhLeafFlag)) stack.push_back(ref);
  }
  return live;
}

std::vector<uint8_t> bytes(const vk::Buffer& b, size_t size) { return b.downloadVector<uint8_t>(size); }

}  // namespace

// Positions and leaf entries follow from the tree alone (depth-first), not from the order in
// which atomics run: two builds of one mesh give the same bytes.
TEST_F(GpuBuilder, TwoBuildsGiveTheSameBytes) {
  const bvh::SyntheticMesh mesh = bvh::makeSphere({0, 0, 0}, 1.0f, 200, 50, 0.3f);
  bvh::Bvh first = build(mesh), second = build(mesh);
  ASSERT_EQ(first.nodeCount, second.nodeCount);
  const uint32_t live = liveNodes(first);
  ASSERT_LE(live, first.nodeCount);
  EXPECT_EQ(bytes(first.nodes, live * sizeof(gpu::bvh::BvhNode)), bytes(second.nodes, live * sizeof(gpu::bvh::BvhNode)));
  EXPECT_EQ(bytes(first.traversalNodes, live * sizeof(gpu::bvh::BvhTraversalNode)),
            bytes(second.traversalNodes, live * sizeof(gpu::bvh::BvhTraversalNode)));
  EXPECT_EQ(bytes(first.leafData, first.leafData.size()), bytes(second.leafData, second.leafData.size()));
}

// The renderer's build writes only the form traversal reads, the same bytes as the build of
// both forms: the quantized nodes of a mesh past kQuantizedTraversalFromTriangles, the exact
// ones of a smaller mesh. The other array is one node, and download refuses it.
TEST_F(GpuBuilder, RendererBuildWritesOnlyTheTraversedForm) {
  const bvh::SyntheticMesh large = bvh::makeSphere({0, 0, 0}, 1.0f, 200, 50, 0.3f);  // 20K triangles
  const bvh::SyntheticMesh small = bvh::makeSphere({0, 0, 0}, 1.0f, 40, 20, 0.3f);
  ASSERT_TRUE(bvh::quantizedTraversal(uint32_t(large.triangles.size())));
  ASSERT_FALSE(bvh::quantizedTraversal(uint32_t(small.triangles.size())));
  for (const bvh::SyntheticMesh* mesh : {&large, &small}) {
    bvh::Bvh both = build(*mesh), traversed = build(*mesh, nullptr, bvh::NodeForms::Traversed);
    ASSERT_EQ(traversed.quantized, both.quantized);
    const uint32_t live = liveNodes(both);
    ASSERT_LE(live, both.nodeCount);
    const size_t nodeBytes = traversed.quantized ? sizeof(gpu::bvh::BvhTraversalNode) : sizeof(gpu::bvh::BvhNode);
    EXPECT_EQ(bytes(traversed.traversedNodes(), live * nodeBytes), bytes(both.traversedNodes(), live * nodeBytes));
    EXPECT_EQ(bytes(traversed.leafData, traversed.leafData.size()), bytes(both.leafData, both.leafData.size()));
    const vk::Buffer& other = traversed.quantized ? traversed.nodes : traversed.traversalNodes;
    EXPECT_EQ(other.size(), traversed.quantized ? sizeof(gpu::bvh::BvhNode) : sizeof(gpu::bvh::BvhTraversalNode));
    EXPECT_EQ(traversed.hasExactNodes, !traversed.quantized);
    EXPECT_EQ(traversed.hasQuantizedNodes, traversed.quantized);
    if (traversed.quantized) {
      EXPECT_THROW(bvh::download(traversed), std::logic_error);
    } else {
      EXPECT_NO_THROW(bvh::download(traversed));
    }
    traversed.quantized = !traversed.quantized;  // the form that was not built
    EXPECT_THROW(traversed.makeTexelViews(test::context()), std::logic_error);
  }
}

TEST_F(GpuBuilder, SahWithinTenPercentOfCpuBinnedSah) {
  auto meshes = test::testMeshes();
  meshes.push_back({"bumpy_sphere_80k", bvh::makeSphere({0, 0, 0}, 1.0f, 400, 100, 0.3f)});
  for (const auto& [name, mesh] : meshes) {
    if (mesh.triangles.size() < 100) continue;  // too few nodes for a ratio to mean much
    double gpuSah = bvh::sahCost(bvh::download(build(mesh)));
    double cpuSah = bvh::sahCost(bvh::buildCpu(mesh.vertices, mesh.triangles));
    EXPECT_LE(gpuSah, 1.1 * cpuSah) << name << ": GPU " << gpuSah << " CPU " << cpuSah;
    std::printf("%s: SAH gpu %.3f cpu %.3f ratio %.3f\n", name.c_str(), gpuSah, cpuSah, gpuSah / cpuSah);
  }
}

TEST_F(GpuBuilder, TreeletRestructuringLowersSah) {
  bvh::SyntheticMesh mesh = bvh::makeSphere({0, 0, 0}, 1.0f, 100, 50, 0.3f);
  mesh.append(bvh::makeSoup(2000, 9, {0, 0, 0}, 1.5f, 0.1f));
  bvh::GpuBuildOptions plain;
  plain.treeletRounds = 0;  // explicit: overrides the default's choice by size
  DeviceMesh dm(test::context(), mesh);
  double lbvh = bvh::sahCost(bvh::download(
      bvh::buildGpu(test::context(), dm.vertices, dm.triangles, uint32_t(mesh.triangles.size()), plain, nullptr,
                    bvh::NodeForms::Both)));
  bvh::HostBvh restructured = bvh::download(build(mesh));
  EXPECT_EQ(bvh::checkInvariants(restructured, mesh.vertices, mesh.triangles), "");
  EXPECT_LT(bvh::sahCost(restructured), 0.95 * lbvh);
}

// The default rounds (bvh::treeletRoundsFor): two for a scene traversed with exact nodes, one for
// a quantized one; the second round lowers the reference scenes' SAH below one round's by at
// least 3% (measured 6-7%) and the tree stays valid.
TEST_F(GpuBuilder, DefaultRoundsFollowTheSceneSize) {
  const bvh::SyntheticMesh large = bvh::makeSphere({0, 0, 0}, 1.0f, 200, 50, 0.3f);  // 20K triangles
  bvh::BuildStats stats;
  build(large, &stats);
  EXPECT_EQ(stats.treeletRounds, 1u);
  bvh::GpuBuildOptions one;
  one.treeletRounds = 1;
  const bvh::GpuBuilder oneRound(test::context(), one);  // its pipelines compiled once for both scenes
  for (const char* file : {"cornell/cornell.gltf", "room/room.gltf"}) {
    scene::Scene sc = scene::loadScene(test::referencePath(file));
    bvh::SyntheticMesh mesh{sc.vertices, sc.triangles};
    bvh::HostBvh host = bvh::download(build(mesh, &stats));
    EXPECT_EQ(stats.treeletRounds, 2u) << file;
    EXPECT_EQ(bvh::checkInvariants(host, mesh.vertices, mesh.triangles), "") << file;
    DeviceMesh dm(test::context(), mesh);
    const double oneRoundSah = bvh::sahCost(bvh::download(
        oneRound.build(dm.vertices, dm.triangles, uint32_t(mesh.triangles.size()), nullptr, bvh::NodeForms::Both)));
    EXPECT_LT(bvh::sahCost(host), 0.97 * oneRoundSah) << file;
    std::printf("%s: SAH two rounds %.3f, one round %.3f\n", file, bvh::sahCost(host), oneRoundSah);
  }
}

TEST_F(GpuBuilder, ClosestHitsMatchBruteForce) {
  auto& ctx = test::context();
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::Bvh tree = build(mesh);
    uint32_t count = mesh.triangles.size() > 100 ? 100000 : 20000;
    auto rays = test::randomRays(mesh, count, 21);
    auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
    EXPECT_EQ(test::compareClosest(name, mesh, rays, hits), 0u) << name;
  }
}

TEST_F(GpuBuilder, RefusesScenesPastTheDeviceLimit) {
  auto& ctx = test::context();
  bvh::SyntheticMesh m = bvh::makeSoup(4, 1, {0, 0, 0}, 1, 1);
  DeviceMesh dm(ctx, m);
  const bvh::TriangleLimit limit = bvh::triangleLimit(ctx);
  try {
    bvh::buildGpu(ctx, dm.vertices, dm.triangles, limit.triangles + 1);
    FAIL() << "expected a DeviceError";
  } catch (const DeviceError& e) {
    // One line naming the size and the device limit that refuses it.
    std::string what = e.what();
    EXPECT_NE(what.find(std::to_string(limit.triangles + 1) + " triangles"), std::string::npos) << what;
    EXPECT_NE(what.find(limit.limit), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(bvh::buildGpu(ctx, dm.vertices, dm.triangles, 0), InputError);
}

TEST_F(GpuBuilder, ReferenceScenes) {
  auto& ctx = test::context();
  for (const char* file : {"cornell/cornell.gltf", "room/room.gltf"}) {
    scene::Scene sc = scene::loadScene(test::referencePath(file));
    bvh::SyntheticMesh mesh{sc.vertices, sc.triangles};
    bvh::BuildStats stats;
    bvh::Bvh tree = build(mesh, &stats);
    bvh::HostBvh host = bvh::download(tree);
    EXPECT_EQ(bvh::checkInvariants(host, mesh.vertices, mesh.triangles), "") << file;
    double cpuSah = bvh::sahCost(bvh::buildCpu(mesh.vertices, mesh.triangles));
    EXPECT_LE(bvh::sahCost(host), 1.1 * cpuSah) << file;
    auto rays = test::randomRays(mesh, 100000, 31);
    auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
    EXPECT_EQ(test::compareClosest(file, mesh, rays, hits), 0u) << file;
    std::printf("%s: %zu triangles, SAH gpu %.3f cpu %.3f\n", file, mesh.triangles.size(),
                bvh::sahCost(host), cpuSah);
  }
}

// PLOC (shared/bvh_build.h), forced on every test mesh (the default takes it from
// kPlocFromTriangles triangles): a valid tree whose statistics match the download, SAH within
// 1.1x of the CPU binned-SAH tree, the closest hits of the brute-force loop, and the same bytes
// from two builds. The
// meshes include degenerate triangles, huge and tiny coordinates and three triangles (the root's
// index may then be another than 0, which bvh_ploc_root swaps with the node at 0).
TEST_F(GpuBuilder, PlocTreesAreValidAndTraceExactly) {
  auto& ctx = test::context();
  bvh::GpuBuildOptions options;
  options.hierarchy = bvh::Hierarchy::Ploc;
  const bvh::GpuBuilder ploc(ctx, options);
  // The depth-first layout takes its subtree node counts from PLOC's merges, kept by the treelet
  // round that follows (no bvh_subtree_count): also right without that round, and with one that
  // restructures every node (so that every count is rewritten). And with bvh_ploc_local's
  // merges within chunks (two rounds: the second merges nodes the first made), where the device
  // has subgroup shuffles. The tail (bvh_ploc_tail: by default all but the first iteration or two
  // on these meshes) makes the same tree, byte for byte, in as many iterations as the global
  // iterations alone, or with a tail from 8 clusters.
  struct Other {
    std::string what;
    std::unique_ptr<bvh::GpuBuilder> builder;
    uint32_t localRounds = 0;  // bvh_ploc_local rounds it must have run
    bool sameTree = false;     // the default's tree, byte for byte
  };
  std::vector<Other> others;
  for (uint32_t tailClusters : {0u, 8u}) {
    bvh::GpuBuildOptions other = options;
    other.plocTailClusters = tailClusters;
    others.push_back({"tail from " + std::to_string(tailClusters) + " clusters", std::make_unique<bvh::GpuBuilder>(ctx, other),
                      0, true});
  }
  for (uint32_t minTriangles : {0u, 7u}) {
    bvh::GpuBuildOptions other = options;
    other.plocTreeletMinTriangles = minTriangles;
    others.push_back({"treelets from " + std::to_string(minTriangles), std::make_unique<bvh::GpuBuilder>(ctx, other)});
  }
  if (bvh::PlocPass::localMergesSupported(ctx)) {
    bvh::GpuBuildOptions other = options;
    other.plocLocalRounds = 2;
    others.push_back({"two local rounds", std::make_unique<bvh::GpuBuilder>(ctx, other), 2});
  }
  auto meshes = test::testMeshes();
  meshes.push_back({"two_triangles", bvh::makeSoup(2, 7, {0, 0, 0}, 1.0f, 0.5f)});
  for (const auto& [name, mesh] : meshes) {
    const uint32_t n = uint32_t(mesh.triangles.size());
    DeviceMesh dm(ctx, mesh);
    bvh::BuildStats stats;
    bvh::Bvh tree = ploc.build(dm.vertices, dm.triangles, n, &stats, bvh::NodeForms::Both);
    bvh::HostBvh host = bvh::download(tree);
    EXPECT_EQ(bvh::checkInvariants(host, mesh.vertices, mesh.triangles), "") << name;
    EXPECT_EQ(stats.depth, bvh::depth(host)) << name;
    EXPECT_NEAR(stats.sahCost, bvh::sahCost(host), 1e-3 * bvh::sahCost(host)) << name;
    // Every iteration merges at least one pair: n - 1 merges take at most n - 1 iterations.
    if (n > 1) {
      EXPECT_GT(stats.plocIterations, 0u) << name;
      EXPECT_LE(stats.plocIterations, n - 1) << name;
    }
    if (n >= 100) {
      double cpuSah = bvh::sahCost(bvh::buildCpu(mesh.vertices, mesh.triangles));
      EXPECT_LE(bvh::sahCost(host), 1.1 * cpuSah) << name;
      std::printf("%s: PLOC SAH %.3f, CPU %.3f, %u iterations\n", name.c_str(), bvh::sahCost(host), cpuSah,
                  stats.plocIterations);
    }
    auto rays = test::randomRays(mesh, n > 100 ? 100000 : 20000, 23);
    auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
    EXPECT_EQ(test::compareClosest(name, mesh, rays, hits), 0u) << name;
    // Node indices follow from the tree, not from the order in which invocations ran.
    bvh::Bvh again = ploc.build(dm.vertices, dm.triangles, n, nullptr, bvh::NodeForms::Both);
    const uint32_t live = liveNodes(tree);
    EXPECT_EQ(bytes(tree.nodes, live * sizeof(gpu::bvh::BvhNode)), bytes(again.nodes, live * sizeof(gpu::bvh::BvhNode)))
        << name;
    EXPECT_EQ(bytes(tree.leafData, tree.leafData.size()), bytes(again.leafData, again.leafData.size())) << name;
    for (const auto& [how, builder, localRounds, sameTree] : others) {
      bvh::BuildStats otherStats;
      bvh::Bvh t = builder->build(dm.vertices, dm.triangles, n, &otherStats, bvh::NodeForms::Both);
      const std::string what = name + ", " + how;
      EXPECT_EQ(bvh::checkInvariants(bvh::download(t), mesh.vertices, mesh.triangles), "") << what;
      if (sameTree) {
        EXPECT_EQ(otherStats.plocIterations, stats.plocIterations) << what;
        EXPECT_EQ(liveNodes(t), live) << what;
        EXPECT_EQ(bytes(t.nodes, live * sizeof(gpu::bvh::BvhNode)), bytes(tree.nodes, live * sizeof(gpu::bvh::BvhNode)))
            << what;
        EXPECT_EQ(bytes(t.leafData, t.leafData.size()), bytes(tree.leafData, tree.leafData.size())) << what;
      }
      if (localRounds != 0 && n > 1) {  // the rounds ran (PLOC needs two triangles), and their node
        // indices follow from the tree too
        EXPECT_EQ(otherStats.plocLocalRounds, localRounds) << what;
        bvh::Bvh u = builder->build(dm.vertices, dm.triangles, n, nullptr, bvh::NodeForms::Both);
        const uint32_t liveT = liveNodes(t);
        EXPECT_EQ(bytes(t.nodes, liveT * sizeof(gpu::bvh::BvhNode)), bytes(u.nodes, liveT * sizeof(gpu::bvh::BvhNode)))
            << what;
        EXPECT_EQ(bytes(t.leafData, t.leafData.size()), bytes(u.leafData, u.leafData.size())) << what;
      }
      const decltype(rays) some(rays.begin(), rays.begin() + std::min<size_t>(rays.size(), 20000));
      EXPECT_EQ(test::compareClosest(what, mesh, some, test::traceOnDevice(ctx, t, some, gpu::bvh_trace::kModeClosest)), 0u)
          << what;
    }
  }
}

// The default builds scenes of kPlocFromTriangles or more by PLOC where they fit one binding,
// smaller ones by LBVH and treelets (asked of plocFor: a build that large takes seconds here).
TEST_F(GpuBuilder, DefaultHierarchyFollowsTheSceneSize) {
  const bvh::GpuBuildOptions automatic;
  EXPECT_TRUE(bvh::plocFor(automatic, bvh::kPlocFromTriangles, true));
  EXPECT_FALSE(bvh::plocFor(automatic, bvh::kPlocFromTriangles, false));  // by address: LBVH
  EXPECT_FALSE(bvh::plocFor(automatic, bvh::kPlocFromTriangles - 1, true));
  bvh::GpuBuildOptions forced;
  forced.hierarchy = bvh::Hierarchy::Ploc;
  EXPECT_TRUE(bvh::plocFor(forced, 2, true));
  EXPECT_FALSE(bvh::plocFor(forced, 1, true));  // one triangle: no interior node to merge
  bvh::BuildStats stats;
  build(bvh::makeSphere({0, 0, 0}, 1.0f, 200, 50, 0.3f), &stats);  // 20K triangles
  EXPECT_EQ(stats.plocIterations, 0u);
  EXPECT_EQ(stats.treeletRounds, 1u);
}

// PLOC at a size where its per-iteration counts pass what one serial loop may count on llvmpipe
// (65535 iterations; the first version lost every cluster past the 65535th subgroup): every
// triangle is placed once, SAH stays within 1.1x of the CPU tree, and closest hits match the
// host tracer over the CPU binned-SAH tree (a brute-force loop is too slow at this size).
TEST_F(GpuBuilder, PlocBuildsSixHundredThousandTriangles) {
  auto& ctx = test::context();
  const bvh::SyntheticMesh mesh = bvh::makeSphere({0, 0, 0}, 1.0f, 775, 390, 0.15f);  // 604,500
  const uint32_t n = uint32_t(mesh.triangles.size());
  ASSERT_GT(n / 8, 65535u);  // more subgroups than one serial loop may visit
  bvh::GpuBuildOptions options;
  options.hierarchy = bvh::Hierarchy::Ploc;
  const bvh::GpuBuilder ploc(ctx, options);
  DeviceMesh dm(ctx, mesh);
  bvh::BuildStats stats;
  bvh::Bvh tree = ploc.build(dm.vertices, dm.triangles, n, &stats, bvh::NodeForms::Both);
  EXPECT_GT(stats.plocIterations, 0u);
  // Here the global iterations run until plocTailClusters are left, and the tail (bvh_ploc_tail)
  // makes the rest of the same tree that the global iterations alone make.
  {
    bvh::GpuBuildOptions noTail = options;
    noTail.plocTailClusters = 0;
    bvh::BuildStats noTailStats;
    bvh::Bvh global = bvh::GpuBuilder(ctx, noTail).build(dm.vertices, dm.triangles, n, &noTailStats, bvh::NodeForms::Both);
    EXPECT_EQ(noTailStats.plocIterations, stats.plocIterations);
    const uint32_t live = liveNodes(tree);
    EXPECT_EQ(bytes(global.nodes, live * sizeof(gpu::bvh::BvhNode)), bytes(tree.nodes, live * sizeof(gpu::bvh::BvhNode)));
    EXPECT_EQ(bytes(global.leafData, global.leafData.size()), bytes(tree.leafData, tree.leafData.size()));
  }
  bvh::HostBvh host = bvh::download(tree);
  EXPECT_EQ(bvh::checkInvariants(host, mesh.vertices, mesh.triangles), "");
  const bvh::HostBvh cpu = bvh::buildCpu(mesh.vertices, mesh.triangles);
  EXPECT_LE(bvh::sahCost(host), 1.1 * bvh::sahCost(cpu));
  const auto cpuLeaves = bvh::makeLeafTriangles(cpu, mesh.vertices, mesh.triangles);
  const bvh::HostTracer reference(cpu, cpuLeaves);
  const auto rays = test::randomRays(mesh, 20000, 41);
  const auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
  uint32_t bad = 0, hit = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const gpu::bvh_trace::TraceHit ref = reference.closest(rays[i]);
    const bool refHits = ref.triangle != gpu::bvh_trace::kNoHit;
    hit += refHits;
    // Equal distance; the triangle may differ only where two are hit at that distance.
    const bool ok = refHits ? hits[i].triangle != gpu::bvh_trace::kNoHit && std::abs(hits[i].t - ref.t) <= 1e-4f * ref.t
                            : hits[i].triangle == gpu::bvh_trace::kNoHit;
    if (!ok && ++bad <= 5)
      ADD_FAILURE() << "ray " << i << ": expected triangle " << ref.triangle << " t " << ref.t << ", got "
                    << hits[i].triangle << " t " << hits[i].t;
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(hit, rays.size() / 4);
}

namespace {

// `count` small triangles along the x axis at doubling distances (x = 2^k, exact in floats): the
// cluster nearest each one is the one before it, so PLOC merges one pair per iteration.
bvh::SyntheticMesh doublingChain(uint32_t count) {
  bvh::SyntheticMesh m;
  for (uint32_t k = 0; k < count; ++k) {
    const float x = std::ldexp(1.0f, int(k)), s = x / 16;
    const uint32_t base = uint32_t(m.vertices.size());
    for (glm::vec3 p : {glm::vec3(x, 0, 0), glm::vec3(x + s, s, 0), glm::vec3(x, 0, s)}) {
      gpu::scene::Vertex v{};
      v.position = p;
      v.normal = {0, 0, 1};
      m.vertices.push_back(v);
    }
    m.triangles.push_back({base, base + 1, base + 2, 0});
  }
  return m;
}

}  // namespace

// The build's two retries. A chain that PLOC merges one pair per iteration needs more global
// iterations than the first recording's estimate (PlocPass::Iterations; without a tail): the
// build records again with more and makes the tree that the tail makes in one recording. A
// longer chain gives a PLOC tree deeper than kBvhMaxDepth: the build falls back to a plain LBVH.
TEST_F(GpuBuilder, PlocRetriesWithMoreIterationsAndFallsBackToLbvhPastMaxDepth) {
  auto& ctx = test::context();
  bvh::GpuBuildOptions options;
  options.hierarchy = bvh::Hierarchy::Ploc;
  bvh::GpuBuildOptions noTail = options;
  noTail.plocTailClusters = 0;
  const bvh::GpuBuilder withTail(ctx, options), globalOnly(ctx, noTail);

  const bvh::SyntheticMesh chain = doublingChain(48);
  const uint32_t n = uint32_t(chain.triangles.size());
  ASSERT_LT(bvh::PlocPass::Iterations(n, 0).count(), n - 1);  // the first recording falls short
  DeviceMesh dm(ctx, chain);
  bvh::BuildStats retried, tailed;
  const bvh::Bvh tree = globalOnly.build(dm.vertices, dm.triangles, n, &retried, bvh::NodeForms::Both);
  const bvh::Bvh reference = withTail.build(dm.vertices, dm.triangles, n, &tailed, bvh::NodeForms::Both);
  EXPECT_EQ(retried.plocIterations, n - 1);
  EXPECT_EQ(tailed.plocTailClusters, options.plocTailClusters);
  const bvh::HostBvh host = bvh::download(tree);
  EXPECT_EQ(bvh::checkInvariants(host, chain.vertices, chain.triangles), "");
  EXPECT_EQ(retried.depth, bvh::depth(host));
  const uint32_t live = liveNodes(tree);
  EXPECT_EQ(liveNodes(reference), live);
  EXPECT_EQ(bytes(tree.nodes, live * sizeof(gpu::bvh::BvhNode)), bytes(reference.nodes, live * sizeof(gpu::bvh::BvhNode)));
  EXPECT_EQ(bytes(tree.leafData, tree.leafData.size()), bytes(reference.leafData, reference.leafData.size()));

  const bvh::SyntheticMesh deep = doublingChain(80);
  const uint32_t m = uint32_t(deep.triangles.size());
  DeviceMesh ddm(ctx, deep);
  for (const bvh::GpuBuilder* builder : {&withTail, &globalOnly}) {
    bvh::BuildStats stats;
    const bvh::HostBvh fallback = bvh::download(builder->build(ddm.vertices, ddm.triangles, m, &stats, bvh::NodeForms::Both));
    EXPECT_EQ(bvh::checkInvariants(fallback, deep.vertices, deep.triangles), "");
    EXPECT_EQ(stats.plocIterations, 0u);  // the LBVH built the tree that was kept
    EXPECT_EQ(stats.treeletRounds, 0u);
    EXPECT_EQ(stats.depth, bvh::depth(fallback));
    EXPECT_LE(stats.depth, gpu::bvh::kBvhMaxDepth);
  }
  // The plain LBVH of the same mesh, built as such: the same tree.
  bvh::GpuBuildOptions plain;
  plain.hierarchy = bvh::Hierarchy::Lbvh;
  plain.treeletRounds = 0;
  bvh::BuildStats s1, s2;
  const bvh::Bvh lbvh = bvh::GpuBuilder(ctx, plain).build(ddm.vertices, ddm.triangles, m, &s1, bvh::NodeForms::Both);
  const bvh::Bvh fellBack = withTail.build(ddm.vertices, ddm.triangles, m, &s2, bvh::NodeForms::Both);
  const uint32_t liveLbvh = liveNodes(lbvh);
  EXPECT_EQ(bytes(lbvh.nodes, liveLbvh * sizeof(gpu::bvh::BvhNode)), bytes(fellBack.nodes, liveLbvh * sizeof(gpu::bvh::BvhNode)));
  std::printf("chain of %u: PLOC %u iterations, depth %u; chain of %u: fallback depth %u\n", n, retried.plocIterations,
              retried.depth, m, s2.depth);
}

// PLOC's iteration policy: the first estimate (without and with a tail), then twice as many
// after a recording that left more than one cluster, up to the triangle count, then a refusal.
TEST(PlocIterations, GrowUntilEveryMergeFits) {
  bvh::PlocPass::Iterations global(100, 0);
  EXPECT_EQ(global.count(), 16u + 4u * 7u);  // 16 + 4 ceil(log2 n)
  EXPECT_TRUE(global.complete(1));
  EXPECT_EQ(global.count(), 44u);
  EXPECT_FALSE(global.complete(5));
  EXPECT_EQ(global.count(), 88u);
  EXPECT_FALSE(global.complete(2));
  EXPECT_EQ(global.count(), 100u);
  EXPECT_THROW(global.complete(2), DeviceError);
  EXPECT_EQ(bvh::PlocPass::Iterations(1u << 20, 1024).count(), 30u);  // 2 + ceil(4 ln(n / tail))
  EXPECT_EQ(bvh::PlocPass::Iterations(500, 1024).count(), 2u);
  EXPECT_EQ(bvh::PlocPass::Iterations(3, 0).count(), 3u);
}
