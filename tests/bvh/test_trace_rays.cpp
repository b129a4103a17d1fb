// bvh_trace_rays(.comp) and lib/bvh_traverse.glsl against a brute-force CPU loop over every
// triangle: closest hits (the loop's, t within 1e-4 relative, or a rare near-tie that exact
// arithmetic cannot separate from it: closest_hit_rule.h), any-hit agreeing with the closest
// hit, and alpha-masked triangles skipped by both queries. Trees come from the
// CPU builder here; tests/bvh/test_gpu_builder.cpp runs the same checks on GPU-built trees.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "bvh/cpu_builder.h"
#include "bvh/trace_rays.h"
#include "bvh_test_util.h"
#include "common/vk_test.h"
#include "trace_test_util.h"

using namespace osr;

namespace {
// The CPU builder's tree of `mesh`, uploaded.
bvh::Bvh cpuTree(const bvh::SyntheticMesh& mesh) {
  return bvh::upload(test::context(), bvh::buildCpu(mesh.vertices, mesh.triangles), mesh.vertices, mesh.triangles);
}
}  // namespace

TEST(TraceRays, ClosestHitsMatchBruteForceOnCpuTrees) {
  auto& ctx = test::context();
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::Bvh tree = cpuTree(mesh);
    uint32_t count = mesh.triangles.size() > 100 ? 100000 : 20000;
    auto rays = test::randomRays(mesh, count, 7);
    auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
    EXPECT_EQ(test::compareClosest(name, mesh, rays, hits), 0u) << name;
  }
}

// Traversal reads exact nodes or quantized ones (Bvh::quantized, chosen by the triangle count):
// both formats, read either way, give the brute-force closest hits, at every scale of the test
// meshes (1e-6 to 1e6) and on each one's tree.
TEST(TraceRays, ExactAndQuantizedNodesMatchBruteForce) {
  auto& ctx = test::context();
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::Bvh tree = cpuTree(mesh);
    auto rays = test::randomRays(mesh, 20000, 13);
    for (bool quantized : {false, true}) {
      tree.quantized = quantized;
      tree.makeTexelViews(ctx);
      for (bvh::Access access : {bvh::Access::Storage, bvh::Access::TexelFetch}) {
        auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest, nullptr, access);
        EXPECT_EQ(test::compareClosest(name, mesh, rays, hits), 0u)
            << name << (quantized ? " quantized" : " exact") << (access == bvh::Access::Storage ? " storage" : " texels");
      }
    }
  }
}

// Traversal reads the BVH through texel buffers or storage buffers (shared/bvh.h); both must
// give the brute-force hits, and the same bits, for both queries and with alpha masks.
TEST(TraceRays, StorageAndTexelFetchReadsAgree) {
  auto& ctx = test::context();
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::Bvh tree = cpuTree(mesh);
    auto rays = test::randomRays(mesh, 20000, 11);
    std::vector<uint32_t> mask(mesh.triangles.size());
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = uint32_t(i % 3);  // opaque, cut, half cut
    for (uint32_t mode : {gpu::bvh_trace::kModeClosest, gpu::bvh_trace::kModeAny}) {
      const std::vector<uint32_t>* masks[] = {nullptr, &mask};
      for (const std::vector<uint32_t>* m : masks) {
        auto storage = test::traceOnDevice(ctx, tree, rays, mode, m, bvh::Access::Storage);
        auto texel = test::traceOnDevice(ctx, tree, rays, mode, m, bvh::Access::TexelFetch);
        ASSERT_EQ(storage.size(), texel.size());
        size_t differ = 0;
        for (size_t i = 0; i < storage.size(); ++i)
          differ += std::memcmp(&storage[i], &texel[i], sizeof(storage[i])) != 0;
        EXPECT_EQ(differ, 0u) << name << " mode " << mode << (m ? " masked" : "");
        if (mode == gpu::bvh_trace::kModeClosest && !m) {
          EXPECT_EQ(test::compareClosest(name, mesh, rays, storage), 0u) << name;
        }
      }
    }
  }
}

// Each subgroup traces a pool of rays, a lane taking the next when its ray is done
// (lib/bvh_trace_rays_main.glsl). Any pool size must give the bits of one ray per invocation,
// for both queries and with alpha masks, including ray counts that end mid-pool and batches
// smaller than one pool.
TEST(TraceRays, RayPoolsGiveTheBitsOfOneRayPerInvocation) {
  auto& ctx = test::context();
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::Bvh tree = cpuTree(mesh);
    std::vector<uint32_t> mask(mesh.triangles.size());
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = uint32_t(i % 3);  // opaque, cut, half cut
    for (uint32_t count : {5u, 20011u}) {
      auto rays = test::randomRays(mesh, count, 13);
      for (uint32_t mode : {gpu::bvh_trace::kModeClosest, gpu::bvh_trace::kModeAny}) {
        const std::vector<uint32_t>* masks[] = {nullptr, &mask};
        for (const std::vector<uint32_t>* m : masks) {
          auto single = test::traceOnDevice(ctx, tree, rays, mode, m, bvh::Access::Auto, 1);
          for (uint32_t perLane : {3u, 16u, 64u}) {
            auto pooled = test::traceOnDevice(ctx, tree, rays, mode, m, bvh::Access::Auto, perLane);
            ASSERT_EQ(single.size(), pooled.size());
            size_t differ = 0;
            for (size_t i = 0; i < single.size(); ++i)
              differ += std::memcmp(&single[i], &pooled[i], sizeof(single[i])) != 0;
            EXPECT_EQ(differ, 0u) << name << " rays " << count << " per lane " << perLane << " mode "
                                  << mode << (m ? " masked" : "");
          }
          if (mode == gpu::bvh_trace::kModeClosest && !m) {
            EXPECT_EQ(test::compareClosest(name, mesh, rays, single), 0u) << name;
          }
        }
      }
    }
  }
}

TEST(TraceRays, AnyHitAgreesWithClosestHit) {
  auto& ctx = test::context();
  for (const auto& [name, mesh] : test::testMeshes()) {
    bvh::Bvh tree = cpuTree(mesh);
    auto rays = test::randomRays(mesh, 20000, 8, /*randomTMax=*/true);
    auto closest = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
    auto any = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeAny);
    uint32_t bad = 0, occluded = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      bool c = closest[i].triangle != gpu::bvh_trace::kNoHit;
      bool a = any[i].triangle != gpu::bvh_trace::kNoHit;
      occluded += c;
      if (c != a && ++bad <= 5) ADD_FAILURE() << name << ": ray " << i << " closest " << c << " any " << a;
    }
    EXPECT_EQ(bad, 0u) << name;
    EXPECT_GT(occluded, 0u) << name;
    EXPECT_LT(occluded, rays.size()) << name;
  }
}

TEST(TraceRays, AlphaMaskedTrianglesAreSkipped) {
  auto& ctx = test::context();
  auto meshes = test::testMeshes();
  const auto& mesh = meshes[0].mesh;
  bvh::Bvh tree = cpuTree(mesh);
  std::mt19937 rng(3);
  std::vector<uint32_t> mask(mesh.triangles.size());
  for (auto& m : mask) m = rng() % 3;  // opaque, cut everywhere, cut near v0
  auto rays = test::randomRays(mesh, 100000, 9);
  auto hits = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest, &mask);
  EXPECT_EQ(test::compareClosest("alpha closest", mesh, rays, hits, &mask), 0u);
  // Any-hit with the same mask: occluded exactly when the masked closest hit exists.
  auto occl = test::randomRays(mesh, 20000, 10, /*randomTMax=*/true);
  auto any = test::traceOnDevice(ctx, tree, occl, gpu::bvh_trace::kModeAny, &mask);
  EXPECT_EQ(test::compareOccluded("alpha any-hit", mesh, occl, any, &mask), 0u);
  // The mask changes the answer for some rays, so the test can tell it is applied.
  auto unmasked = test::traceOnDevice(ctx, tree, rays, gpu::bvh_trace::kModeClosest);
  uint32_t changed = 0;
  for (size_t i = 0; i < rays.size(); ++i) changed += unmasked[i].triangle != hits[i].triangle;
  EXPECT_GT(changed, rays.size() / 20);
}
