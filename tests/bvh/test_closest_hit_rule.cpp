// closest_hit_rule.h, the traversal tests' acceptance rule, on the host (no device): hand-made
// rays where the answer is known, the closest hits of exact arithmetic (another arithmetic that
// is right), deliberately wrong answers, and the near-tie budget.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "bvh_test_util.h"
#include "closest_hit_rule.h"

using namespace osr;
using gpu::bvh_trace::kNoHit;
using test::TraceHit;
using test::TraceRay;
using test::Verdict;

namespace {

bvh::SyntheticMesh meshOf(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles) {
  bvh::SyntheticMesh m;
  for (const glm::vec3& p : positions) {
    gpu::scene::Vertex v{};
    v.position = p;
    v.normal = glm::vec3(0, 0, 1);
    m.vertices.push_back(v);
  }
  for (const glm::uvec3& t : triangles) m.triangles.push_back({t.x, t.y, t.z, 0});
  return m;
}

// T0 in the plane z = 0 over (0,0), (1,0), (0,1); T1 shares T0's edge from (1,0,0) to (0,1,0)
// and folds back under it to (0,0,-0.02): straight down at (x, y) it lies 0.02 (1 - x - y)
// below T0.
bvh::SyntheticMesh wedge() {
  return meshOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -0.02f}}, {{0, 1, 2}, {1, 2, 3}});
}
bvh::SyntheticMesh oneTriangle() { return meshOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}); }

// Straight down onto z = 0 at (x, y), from z = 1: t is the depth below z = 1.
TraceRay down(float x, float y, float tMax = std::numeric_limits<float>::infinity()) {
  return {glm::vec3(x, y, 1), 0.0f, glm::vec3(0, 0, -1), tMax};
}

TraceHit reference(const bvh::SyntheticMesh& m, const TraceRay& r, const std::vector<uint32_t>* mask = nullptr) {
  return test::BruteForce(m).closest(r, mask);
}

TraceHit hitOn(uint32_t triangle, float t) { return {t, triangle, glm::vec2(0)}; }
const TraceHit kMiss{0.0f, kNoHit, glm::vec2(0)};

// The closest hit of exact arithmetic: the smallest plane t among triangles the ray passes
// strictly inside (double precision stands in for exact here).
TraceHit exactClosest(const bvh::SyntheticMesh& m, const TraceRay& r) {
  TraceHit best{r.tMax, kNoHit, glm::vec2(0)};
  double bestT = r.tMax;
  for (uint32_t i = 0; i < m.triangles.size(); ++i) {
    const test::Crossing c = test::crossing(m, r, i, nullptr);
    if (c.margin > 0.0 && c.t > r.tMin && c.t < bestT) {
      bestT = c.t;
      best = {float(c.t), i, glm::vec2(0)};
    }
  }
  return best;
}

// The watertight test of bvh/ray_triangle.h in another float arithmetic, as a GPU driver may
// compile it: the shear and the hit's t with fused multiply-adds, and each division 2 ulps
// high (the edge functions stay unfused, as `precise` keeps them).
bool intersectOtherArithmetic(const TraceRay& ray, glm::vec3 v0, glm::vec3 v1, glm::vec3 v2, float tFar,
                              float& t) {
  auto divide = [](float a, float b) {
    const float q = a / b;
    return std::nextafter(std::nextafter(q, 2 * q), 2 * q);
  };
  const bvh::ShearedRay r(ray.origin, ray.dir);
  const glm::vec3 shear(divide(ray.dir[r.kx], ray.dir[r.kz]), divide(ray.dir[r.ky], ray.dir[r.kz]),
                        divide(1.0f, ray.dir[r.kz]));
  const glm::vec3 v[3] = {v0 - ray.origin, v1 - ray.origin, v2 - ray.origin};
  float x[3], y[3], z[3];
  for (int i = 0; i < 3; ++i) {
    x[i] = std::fma(-shear.x, v[i][r.kz], v[i][r.kx]);
    y[i] = std::fma(-shear.y, v[i][r.kz], v[i][r.ky]);
    z[i] = shear.z * v[i][r.kz];
  }
  const float U = x[2] * y[1] - y[2] * x[1], V = x[0] * y[2] - y[0] * x[2], W = x[1] * y[0] - y[1] * x[0];
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  const float det = U + V + W;
  if (det == 0.0f) return false;
  t = std::fma(U, z[0], std::fma(V, z[1], W * z[2])) * divide(1.0f, det);
  return t > ray.tMin && t < tFar;
}

TraceHit otherArithmeticClosest(const bvh::SyntheticMesh& m, const TraceRay& r) {
  TraceHit best{r.tMax, kNoHit, glm::vec2(0)};
  for (uint32_t i = 0; i < m.triangles.size(); ++i) {
    const auto& tri = m.triangles[i];
    float t;
    if (intersectOtherArithmetic(r, m.vertices[tri.v0].position, m.vertices[tri.v1].position,
                                 m.vertices[tri.v2].position, best.t, t))
      best = {t, i, glm::vec2(0)};
  }
  return best;
}

}  // namespace

TEST(ClosestHitRule, TheReferenceItselfMatches) {
  const auto m = wedge();
  for (const TraceRay& r : {down(0.25f, 0.25f), down(0.5f, 0.5f), down(2.0f, 2.0f)}) {
    const TraceHit ref = reference(m, r);
    EXPECT_EQ(test::judgeClosest(m, r, ref, ref), Verdict::Match);
  }
  // The same triangle within the tolerance the tests always allowed.
  const TraceHit ref = reference(m, down(0.25f, 0.25f));
  EXPECT_EQ(test::judgeClosest(m, down(0.25f, 0.25f), ref, hitOn(ref.triangle, ref.t * (1 + 5e-5f))), Verdict::Match);
}

// A grazing ray: the plane's rounding moves t by slack / cos, so 1.5e-4 farther is a near-tie
// (NVIDIA's arithmetic gave such t on one_triangle); head-on the same 1.5e-4 is wrong.
TEST(ClosestHitRule, SameTriangleFartherOnlyWhereTheRayGrazes) {
  const auto m = wedge();
  const glm::vec3 dir(1, 0, -0.002f);
  const TraceRay grazing{glm::vec3(0.3f, 0.3f, 0) - dir, 0.0f, dir, std::numeric_limits<float>::infinity()};
  const TraceHit ref = reference(m, grazing);
  ASSERT_EQ(ref.triangle, 0u);
  EXPECT_EQ(test::judgeClosest(m, grazing, ref, hitOn(0, ref.t * (1 + 1.5e-4f))), Verdict::NearTie);
  EXPECT_EQ(test::judgeClosest(m, grazing, ref, hitOn(0, ref.t * 1.05f)), Verdict::Wrong);
  const TraceRay headOn = down(0.25f, 0.25f);
  const TraceHit ref2 = reference(m, headOn);
  ASSERT_EQ(ref2.triangle, 0u);
  EXPECT_EQ(test::judgeClosest(m, headOn, ref2, hitOn(0, ref2.t * (1 + 1.5e-4f))), Verdict::Wrong);
}

// A sliver the ray grazes: its float edge functions are all error, so the test's weights can be
// anything and its t anything between the vertices' depths along the dominant axis (z here,
// a[z] / dir[z]), which the NVIDIA H200 gave on degenerate_soup and huge_coordinates. Seen
// obliquely, this sliver's orthogonal depths are all 1, its depths along z 0.9 to 1.1: a hit at
// 1.05 is a near-tie, one at 1.15 is not, nor is 1.05 on a ray that passes 0.01 away.
TEST(ClosestHitRule, SliverHitAnywhereBetweenItsDepthsAlongTheDominantAxis) {
  // The ray meets z = 0 at (0.5, -1e-7, 0) at t = 1; the sliver runs from (0.3, 0, -0.1) to
  // (0.7, 0, 0.1), perpendicular to the ray, with its third vertex 1e-7 off that edge.
  const auto m = meshOf({{0.3f, 0, -0.1f}, {0.7f, 0, 0.1f}, {0.5f, 1e-7f, 0}}, {{0, 1, 2}});
  const glm::vec3 dir(0.5f, 0, -1);
  const TraceRay grazing{glm::vec3(0.5f, -1e-7f, 0) - dir, 0.0f, dir, std::numeric_limits<float>::infinity()};
  const TraceRay clear{glm::vec3(0.5f, -0.01f, 0) - dir, 0.0f, dir, std::numeric_limits<float>::infinity()};
  ASSERT_EQ(reference(m, grazing).triangle, kNoHit);
  ASSERT_EQ(reference(m, clear).triangle, kNoHit);
  EXPECT_EQ(test::judgeClosest(m, grazing, kMiss, hitOn(0, 1.05f)), Verdict::NearTie);
  EXPECT_EQ(test::judgeClosest(m, grazing, kMiss, hitOn(0, 0.95f)), Verdict::NearTie);
  EXPECT_EQ(test::judgeClosest(m, grazing, kMiss, hitOn(0, 1.15f)), Verdict::Wrong);
  EXPECT_EQ(test::judgeClosest(m, grazing, kMiss, hitOn(0, 0.85f)), Verdict::Wrong);
  EXPECT_EQ(test::judgeClosest(m, clear, kMiss, hitOn(0, 1.05f)), Verdict::Wrong);
}

// Through the shared edge either triangle is right, at (nearly) the same t; away from the edge
// the neighbour behind is wrong, however close.
TEST(ClosestHitRule, NeighbourOnlyAcrossAnEdgeTheRayGrazes) {
  const auto m = wedge();
  for (const TraceRay& r : {down(0.5f, 0.5f), down(0.5f - 1e-7f, 0.5f - 1e-7f)}) {
    const TraceHit ref = reference(m, r);
    ASSERT_NE(ref.triangle, kNoHit);
    const uint32_t other = 1 - ref.triangle;
    EXPECT_EQ(test::judgeClosest(m, r, ref, hitOn(other, ref.t * (1 + 1e-6f))), Verdict::NearTie);
    EXPECT_EQ(test::judgeClosest(m, r, ref, hitOn(other, ref.t * 1.01f)), Verdict::Wrong);
  }
  const TraceRay r = down(0.25f, 0.25f);
  const TraceHit ref = reference(m, r);
  ASSERT_EQ(ref.triangle, 0u);
  // T1 is hit there, 1% farther (t = 1.01): the second-closest hit, not a tie.
  EXPECT_EQ(test::judgeClosest(m, r, ref, hitOn(1, 1.01f)), Verdict::Wrong);
  // T1 at T0's distance: T1 is not there.
  EXPECT_EQ(test::judgeClosest(m, r, ref, hitOn(1, ref.t)), Verdict::Wrong);
  // Not a triangle, or t outside the ray.
  EXPECT_EQ(test::judgeClosest(m, r, ref, hitOn(2, ref.t)), Verdict::Wrong);
  EXPECT_EQ(test::judgeClosest(m, r, ref, hitOn(0, -ref.t)), Verdict::Wrong);
}

// A miss is right only where every hit is a graze of the silhouette; a hit the loop missed only
// within rounding of the triangle.
TEST(ClosestHitRule, MissesAndHitsOnlyAtTheSilhouette) {
  const auto m = oneTriangle();
  const TraceRay inside = down(1e-7f, 0.3f), outside = down(-1e-7f, 0.3f);
  ASSERT_EQ(reference(m, inside).triangle, 0u);
  ASSERT_EQ(reference(m, outside).triangle, kNoHit);
  EXPECT_EQ(test::judgeClosest(m, inside, reference(m, inside), kMiss), Verdict::NearTie);
  EXPECT_EQ(test::judgeClosest(m, outside, reference(m, outside), hitOn(0, 1.0f)), Verdict::NearTie);
  const TraceRay clearlyIn = down(0.01f, 0.3f), clearlyOut = down(-0.01f, 0.3f);
  EXPECT_EQ(test::judgeClosest(m, clearlyIn, reference(m, clearlyIn), kMiss), Verdict::Wrong);
  EXPECT_EQ(test::judgeClosest(m, clearlyOut, reference(m, clearlyOut), hitOn(0, 1.0f)), Verdict::Wrong);
  // A miss on the wedge's interior, where both triangles are hit.
  const auto w = wedge();
  EXPECT_EQ(test::judgeClosest(w, down(0.25f, 0.25f), reference(w, down(0.25f, 0.25f)), kMiss), Verdict::Wrong);
}

// An alpha cut is an edge too: at its line either answer, away from it only the loop's.
TEST(ClosestHitRule, AlphaCutIsAnEdge) {
  const auto m = oneTriangle();
  const std::vector<uint32_t> cut{gpu::bvh_trace::kAlphaCutNearV0};  // a hole where 1 - x - y > 0.5
  const TraceRay onCut = down(0.25f, 0.25f), inHole = down(0.1f, 0.1f), visible = down(0.4f, 0.4f);
  EXPECT_EQ(test::judgeClosest(m, onCut, hitOn(0, 1.0f), kMiss, &cut), Verdict::NearTie);
  EXPECT_EQ(test::judgeClosest(m, onCut, kMiss, hitOn(0, 1.0f), &cut), Verdict::NearTie);
  ASSERT_EQ(reference(m, inHole, &cut).triangle, kNoHit);
  EXPECT_EQ(test::judgeClosest(m, inHole, kMiss, hitOn(0, 1.0f), &cut), Verdict::Wrong);
  ASSERT_EQ(reference(m, visible, &cut).triangle, 0u);
  EXPECT_EQ(test::judgeClosest(m, visible, reference(m, visible, &cut), kMiss, &cut), Verdict::Wrong);
  const std::vector<uint32_t> hole{gpu::bvh_trace::kAlphaCutAll};
  EXPECT_EQ(test::judgeClosest(m, visible, kMiss, hitOn(0, 1.0f), &hole), Verdict::Wrong);
}

// Occlusion: a hit at tMax (excluded) may go either way; a clear one may not.
TEST(ClosestHitRule, OcclusionOnlyAtTheEnds) {
  const auto m = oneTriangle();
  EXPECT_EQ(test::judgeOccluded(m, down(0.25f, 0.25f, 1.0f), false, true), Verdict::NearTie);
  EXPECT_EQ(test::judgeOccluded(m, down(0.25f, 0.25f, 1.0f), true, false), Verdict::NearTie);
  EXPECT_EQ(test::judgeOccluded(m, down(0.25f, 0.25f, 0.5f), false, true), Verdict::Wrong);
  EXPECT_EQ(test::judgeOccluded(m, down(0.25f, 0.25f, 2.0f), true, false), Verdict::Wrong);
  EXPECT_EQ(test::judgeOccluded(m, down(1e-7f, 0.3f), true, false), Verdict::NearTie);
  EXPECT_EQ(test::judgeOccluded(m, down(-0.01f, 0.3f), false, true), Verdict::Wrong);
}

// Exact arithmetic is another arithmetic that is right: its closest hits on every test mesh pass,
// with near-ties within the budget.
TEST(ClosestHitRule, AcceptsTheClosestHitsOfExactArithmetic) {
  for (const auto& [name, mesh] : test::testMeshes()) {
    const auto rays = test::randomRays(mesh, 2000, 61);
    std::vector<TraceHit> exact;
    for (const TraceRay& r : rays) exact.push_back(exactClosest(mesh, r));
    EXPECT_EQ(test::compareClosest(name + " exact", mesh, rays, exact), 0u) << name;
  }
}

// So is the same float test compiled another way (fused multiply-adds, a division off by 2
// ulps): the difference a GPU's driver makes, emulated.
TEST(ClosestHitRule, AcceptsTheClosestHitsOfAnotherFloatArithmetic) {
  for (const auto& [name, mesh] : test::testMeshes()) {
    const auto rays = test::randomRays(mesh, 4000, 64);
    std::vector<TraceHit> other;
    for (const TraceRay& r : rays) other.push_back(otherArithmeticClosest(mesh, r));
    EXPECT_EQ(test::compareClosest(name + " fused", mesh, rays, other), 0u) << name;
  }
}

// Deliberately wrong answers on random rays: the second-closest hit in place of the closest, a
// miss in place of a hit. Only a near-tie (a second hit through a shared edge, a graze) passes.
TEST(ClosestHitRule, RejectsSecondClosestHitsAndMisses) {
  for (const auto& [name, mesh] : test::testMeshes()) {
    const auto rays = test::randomRays(mesh, 2000, 62);
    test::BruteForce brute(mesh);
    size_t seconds = 0, secondsRejected = 0, misses = 0, missesRejected = 0;
    std::vector<uint32_t> mask(mesh.triangles.size(), gpu::bvh_trace::kAlphaOpaque);
    for (const TraceRay& r : rays) {
      const TraceHit ref = brute.closest(r);
      if (ref.triangle == kNoHit) continue;
      ++misses;
      missesRejected += test::judgeClosest(mesh, r, ref, kMiss) == Verdict::Wrong;
      mask[ref.triangle] = gpu::bvh_trace::kAlphaCutAll;
      const TraceHit second = brute.closest(r, &mask);
      mask[ref.triangle] = gpu::bvh_trace::kAlphaOpaque;
      if (second.triangle == kNoHit) continue;
      ++seconds;
      secondsRejected += test::judgeClosest(mesh, r, ref, second) == Verdict::Wrong;
    }
    std::printf("%s: rejected %zu of %zu second-closest hits, %zu of %zu misses\n", name.c_str(),
                secondsRejected, seconds, missesRejected, misses);
    EXPECT_GE(secondsRejected + test::nearTieBudget(rays.size()), seconds) << name;
    EXPECT_GE(missesRejected + test::nearTieBudget(rays.size()), misses) << name;
    EXPECT_GT(misses, rays.size() / 10) << name;
  }
}

// Each near-tie is judged right, but a traversal that answers with one on every ray fails:
// every triangle doubled, and the device always naming the twin the loop did not.
TEST(ClosestHitRule, NearTiesPastTheBudgetFail) {
  bvh::SyntheticMesh m = bvh::makeSphere({0, 0, 0}, 1.0f, 16, 8);
  const uint32_t n = uint32_t(m.triangles.size());
  for (uint32_t i = 0; i < n; ++i) m.triangles.push_back(m.triangles[i]);
  const auto rays = test::randomRays(m, 2000, 63);
  test::BruteForce brute(m);
  std::vector<TraceHit> twins;
  size_t nearTies = 0;
  for (const TraceRay& r : rays) {
    const TraceHit ref = brute.closest(r);
    TraceHit twin = ref;
    if (ref.triangle != kNoHit) twin.triangle = ref.triangle < n ? ref.triangle + n : ref.triangle - n;
    nearTies += test::judgeClosest(m, r, ref, twin) == Verdict::NearTie;
    twins.push_back(twin);
  }
  EXPECT_GT(nearTies, rays.size() / 4);
  EXPECT_NONFATAL_FAILURE(test::compareClosest("twins", m, rays, twins), "too many near-ties");
  EXPECT_EQ(test::nearTieBudget(5), 1u);
  EXPECT_EQ(test::nearTieBudget(20000), 100u);
}
