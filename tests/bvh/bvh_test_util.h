// Shared by the BVH tests: test meshes, random rays and the brute-force CPU reference.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "bvh/aabb.h"
#include "bvh/ray_triangle.h"
#include "bvh/synthetic_mesh.h"
#include "closest_hit_rule.h"
#include "shaders/shared/bvh_trace.h"
#include "vk/buffer.h"

namespace osr::test {

using gpu::bvh_trace::TraceHit;
using gpu::bvh_trace::TraceRay;
constexpr float kInf = std::numeric_limits<float>::infinity();

struct NamedMesh {
  std::string name;
  bvh::SyntheticMesh mesh;
};

// Meshes every builder and traversal test runs on: a coherent surface, a soup with degenerate
// triangles, huge and tiny coordinates, and a tiny scene.
inline std::vector<NamedMesh> testMeshes() {
  std::vector<NamedMesh> out;
  bvh::SyntheticMesh mixed = bvh::makeSphere({0, 0, 0}, 1.0f, 32, 16, 0.2f);
  mixed.append(bvh::makeSoup(800, 1, {0.5f, 0, 0}, 2.0f, 0.2f));
  out.push_back({"sphere_and_soup", std::move(mixed)});
  out.push_back({"degenerate_soup", bvh::makeSoup(2000, 2, {0, 0, 0}, 1.0f, 0.15f, 5)});
  bvh::SyntheticMesh huge = bvh::makeSoup(1500, 3, {1e6f, -1e6f, 1e6f}, 1e6f, 1e5f, 11);
  huge.append(bvh::makeSphere({1e6f, -1e6f, 1e6f}, 4e5f, 20, 10));
  out.push_back({"huge_coordinates", std::move(huge)});
  bvh::SyntheticMesh tiny = bvh::makeSoup(1500, 4, {1e-6f, 2e-6f, -1e-6f}, 1e-6f, 2e-7f, 13);
  tiny.append(bvh::makeSphere({1e-6f, 2e-6f, -1e-6f}, 5e-7f, 20, 10));
  out.push_back({"tiny_coordinates", std::move(tiny)});
  out.push_back({"one_triangle", bvh::makeSoup(1, 5, {0, 0, 0}, 0.0f, 1.0f)});
  out.push_back({"three_triangles", bvh::makeSoup(3, 6, {0, 0, 0}, 1.0f, 0.5f)});
  return out;
}

// A device-local buffer of at least 16 bytes (a binding of size 0 is invalid).
inline vk::Buffer deviceBuffer(const vk::Context& ctx, uint64_t bytes, const char* name,
                               VkBufferUsageFlags extraUsage = 0) {
  return vk::Buffer(ctx, std::max<uint64_t>(bytes, 16), vk::MemoryUse::DeviceLocal, name, extraUsage);
}

inline bvh::Aabb meshBounds(const bvh::SyntheticMesh& m) {
  bvh::Aabb b;
  for (const auto& v : m.vertices) b.grow(v.position);
  return b;
}

// Half the rays start anywhere in the (enlarged) bounds in a uniform direction; half aim at a
// random point of a random triangle, so that most of them hit. tMax is infinite unless
// `randomTMax`, which draws it in [0, 2 * diagonal] for occlusion tests.
inline std::vector<TraceRay> randomRays(const bvh::SyntheticMesh& m, uint32_t count, uint32_t seed,
                                        bool randomTMax = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  bvh::Aabb b = meshBounds(m);
  glm::vec3 c = 0.5f * (b.lo + b.hi), half = 0.6f * (b.hi - b.lo);
  float diag = glm::length(b.hi - b.lo);
  if (!(diag > 0.0f)) diag = 1.0f;
  half = glm::max(half, glm::vec3(0.05f * diag));
  std::vector<TraceRay> rays(count);
  for (uint32_t i = 0; i < count; ++i) {
    TraceRay& r = rays[i];
    r.origin = c + half * glm::vec3(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
    glm::vec3 dir;
    if (i % 2 == 0) {
      float z = 2 * u(rng) - 1, phi = 6.2831853f * u(rng), s = std::sqrt(std::max(0.0f, 1 - z * z));
      dir = glm::vec3(s * std::cos(phi), s * std::sin(phi), z);
    } else {
      const auto& t = m.triangles[std::min<size_t>(m.triangles.size() - 1, size_t(u(rng) * m.triangles.size()))];
      float a = u(rng), bb = u(rng);
      if (a + bb > 1) a = 1 - a, bb = 1 - bb;
      glm::vec3 p = m.vertices[t.v0].position * (1 - a - bb) + m.vertices[t.v1].position * a +
                    m.vertices[t.v2].position * bb;
      dir = p - r.origin;
      if (!(glm::length(dir) > 0.0f)) dir = glm::vec3(0, 0, 1);
    }
    r.dir = dir;
    r.tMin = 0.0f;
    r.tMax = randomTMax ? 2.0f * diag * u(rng) / std::max(glm::length(dir), 1e-30f) : kInf;
  }
  return rays;
}

// Alpha cutout of bvh_trace_rays_alpha.comp (shared/bvh_trace.h kAlpha*), on the host.
inline bool alphaCutout(uint32_t mask, glm::vec2 bary) {
  float w0 = 1.0f - bary.x - bary.y;
  return mask == gpu::bvh_trace::kAlphaCutAll ||
         (mask == gpu::bvh_trace::kAlphaCutNearV0 && w0 > 0.5f);
}

// Closest hit over every triangle (kNoHit when none); with `mask`, cut-out hits are skipped.
// Each triangle is first tested against its box enlarged by 1% of its size (far more than any
// rounding of the slab test), which only skips triangles the exact test could not hit.
class BruteForce {
 public:
  explicit BruteForce(const bvh::SyntheticMesh& m) : m_(m) {
    for (const auto& t : m.triangles) {
      bvh::Aabb b;
      for (uint32_t v : {t.v0, t.v1, t.v2}) b.grow(m.vertices[v].position);
      glm::vec3 margin = 0.01f * (b.hi - b.lo) + 1e-6f * glm::max(glm::abs(b.lo), glm::abs(b.hi)) +
                         glm::vec3(1e-30f);
      lo_.push_back(b.lo - margin);
      hi_.push_back(b.hi + margin);
    }
  }
  TraceHit closest(const TraceRay& ray, const std::vector<uint32_t>* mask = nullptr) const {
    bvh::ShearedRay r(ray.origin, ray.dir);
    glm::vec3 inv = 1.0f / ray.dir;
    TraceHit best{ray.tMax, gpu::bvh_trace::kNoHit, glm::vec2(0)};
    for (uint32_t i = 0; i < m_.triangles.size(); ++i) {
      glm::vec3 t0 = (lo_[i] - ray.origin) * inv, t1 = (hi_[i] - ray.origin) * inv;
      glm::vec3 near = glm::min(t0, t1), far = glm::max(t0, t1);
      float enter = std::max(std::max(near.x, near.y), near.z);
      float exit = std::min(std::min(far.x, far.y), far.z);
      // NaN (0 * inf on a slab boundary) compares false and falls through to the exact test.
      if (enter > exit * 1.001f + 1e-30f || exit < 0.0f || enter > best.t * 1.001f) continue;
      const auto& t = m_.triangles[i];
      float th;
      glm::vec2 bary;
      if (!bvh::intersectTriangle(r, m_.vertices[t.v0].position, m_.vertices[t.v1].position,
                                  m_.vertices[t.v2].position, ray.tMin, best.t, th, bary))
        continue;
      if (mask && alphaCutout((*mask)[i], bary)) continue;
      best = {th, i, bary};
    }
    return best;
  }

 private:
  const bvh::SyntheticMesh& m_;
  std::vector<glm::vec3> lo_, hi_;
};

// Compares device closest hits with the brute-force loop by the rule of closest_hit_rule.h:
// returns the number of wrong answers (reporting the first few) and fails when near-ties pass
// their budget. Near-ties are listed on stdout, so that a device's share of them shows.
inline uint32_t compareClosest(const std::string& what, const bvh::SyntheticMesh& m,
                               const std::vector<TraceRay>& rays, const std::vector<TraceHit>& gpu,
                               const std::vector<uint32_t>* mask = nullptr) {
  using gpu::bvh_trace::kNoHit;
  uint32_t bad = 0, hits = 0;
  // Near-ties by kind: the same triangle at another t, another triangle, a device miss, a
  // device hit where the loop missed.
  uint32_t sameTriangle = 0, otherTriangle = 0, deviceMiss = 0, deviceHit = 0;
  BruteForce brute(m);
  for (size_t i = 0; i < rays.size(); ++i) {
    TraceHit ref = brute.closest(rays[i], mask);
    const TraceHit& got = gpu[i];
    hits += ref.triangle != kNoHit;
    const Verdict v = judgeClosest(m, rays[i], ref, got, mask);
    if (v == Verdict::NearTie) {
      uint32_t& kind = got.triangle == kNoHit ? deviceMiss
                       : ref.triangle == kNoHit ? deviceHit
                       : got.triangle == ref.triangle ? sameTriangle
                                                      : otherTriangle;
      ++kind;
      if (sameTriangle + otherTriangle + deviceMiss + deviceHit <= 3) {
        const Crossing c = got.triangle != kNoHit ? crossing(m, rays[i], got.triangle, mask)
                                                  : crossing(m, rays[i], ref.triangle, mask);
        std::printf("%s: near-tie on ray %zu: expected triangle %u t %.9g, got triangle %u t %.9g "
                    "(margin %.3g, slack %.3g, t %.9g +- %.3g)\n",
                    what.c_str(), i, ref.triangle, ref.t, got.triangle, got.t, c.margin, c.slack, c.t,
                    c.tSlack);
      }
    }
    if (v == Verdict::Wrong && ++bad <= 5)
      ADD_FAILURE() << what << ": ray " << i << " expected triangle " << ref.triangle << " t "
                    << ref.t << ", got triangle " << got.triangle << " t " << got.t;
  }
  const uint32_t nearTies = sameTriangle + otherTriangle + deviceMiss + deviceHit;
  if (nearTies > 0)
    std::printf("%s: %u near-ties in %zu rays: %u same triangle, %u other triangle, %u device "
                "miss, %u device hit\n",
                what.c_str(), nearTies, rays.size(), sameTriangle, otherTriangle, deviceMiss, deviceHit);
  EXPECT_LE(nearTies, nearTieBudget(rays.size()))
      << what << ": too many near-ties: " << nearTies << " in " << rays.size() << " rays";
  // The rays must exercise hits, or the comparison proves little.
  EXPECT_GT(hits, rays.size() / 10) << what;
  return bad;
}

// Compares device occlusion answers (any-hit: triangle != kNoHit when occluded) with the
// brute-force loop likewise; returns the number of wrong answers.
inline uint32_t compareOccluded(const std::string& what, const bvh::SyntheticMesh& m,
                                const std::vector<TraceRay>& rays, const std::vector<TraceHit>& gpu,
                                const std::vector<uint32_t>* mask = nullptr) {
  uint32_t bad = 0, nearTies = 0;
  BruteForce brute(m);
  for (size_t i = 0; i < rays.size(); ++i) {
    const bool ref = brute.closest(rays[i], mask).triangle != gpu::bvh_trace::kNoHit;
    const bool got = gpu[i].triangle != gpu::bvh_trace::kNoHit;
    const Verdict v = judgeOccluded(m, rays[i], ref, got, mask);
    if (v == Verdict::NearTie && ++nearTies <= 3)
      std::printf("%s: near-tie on ray %zu: expected occluded %d, got %d\n", what.c_str(), i, ref, got);
    if (v == Verdict::Wrong && ++bad <= 5)
      ADD_FAILURE() << what << ": ray " << i << " expected occluded " << ref << ", got " << got;
  }
  if (nearTies > 0) std::printf("%s: %u near-ties in %zu rays\n", what.c_str(), nearTies, rays.size());
  EXPECT_LE(nearTies, nearTieBudget(rays.size()))
      << what << ": too many near-ties: " << nearTies << " in " << rays.size() << " rays";
  return bad;
}

}  // namespace osr::test
