// The acceptance rule of the traversal tests: when is a device's closest hit (or occlusion
// answer) right, against the brute-force CPU loop?
//
// Both run the same watertight test (bvh/ray_triangle.h, lib/bvh_traverse.glsl), but each
// driver compiles it to its own arithmetic (division, fused multiply-adds outside the `precise`
// edge functions), so the answers agree bit for bit only where both round alike (lavapipe and
// the host). On other devices rays through a shared edge or past a silhouette, and grazing
// rays, can round the other way (docs/device_notes.md, "On an NVIDIA GPU"). So an answer is
// right if it is the loop's, or if exact arithmetic cannot separate it from the loop's: a
// near-tie. Near-ties are judged in double precision against every triangle, and must stay
// rare (kNearTieShare), so that a traversal that answers with a neighbour, a farther hit or a
// miss wherever one is defensible still fails.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/ray_triangle.h"
#include "bvh/synthetic_mesh.h"
#include "shaders/shared/bvh_trace.h"

namespace osr::test {

// Rounding in the float test moves each vertex, as seen from the ray, by a few ulps of its
// distance from the ray's origin: the subtraction, the shear and its division (a driver's
// division may be 2 ulps off, and a fused multiply-add rounds once less). 32 ulps
// (FLT_EPSILON = 2^-23) of the farthest vertex is several times that, and still far below what
// a wrong answer looks like (a neighbour 1e-3 away, a triangle behind).
constexpr double kRoundingSlack = 32.0 / 8388608.0;  // 2^-18
// The relative tolerance on t that the tests have always allowed for the same triangle.
constexpr double kRelativeT = 1e-4;
// Near-ties may be at most this share of the rays of one comparison (and at least one).
constexpr double kNearTieShare = 0.005;

// One triangle against one ray, in double precision: where the ray passes the triangle and how
// far rounding could move that.
struct Crossing {
  // Signed distance, in the plane perpendicular to the ray, from the ray to the boundary of the
  // triangle's visible part (its alpha cut included): positive inside, negative outside.
  double margin = -std::numeric_limits<double>::infinity();
  // How far rounding can move a vertex as seen from the ray: kRoundingSlack * (distance of the
  // farthest vertex from the ray's origin).
  double slack = 0.0;
  // Where the ray meets the triangle's plane, in units of the ray's direction (NaN where the
  // ray sees the triangle edge-on), and how far rounding can move that: the vertices' depths by
  // slack, and the hit's weights by what slack does to the edge functions, times the spread of
  // the depths (a lot on grazing rays and on slivers).
  double t = std::numeric_limits<double>::quiet_NaN();
  double tSlack = std::numeric_limits<double>::infinity();
  // The range of the vertices' depths as the watertight test computes them, widened by slack:
  // a hit's t is a convex combination of those whatever the rounding (see crossing()).
  double tLo = 0.0, tHi = 0.0;

  // The smallest and largest t a float test could give for this triangle.
  double tLowest() const {
    return std::isfinite(t) ? std::max(t - kRelativeT * std::abs(t) - tSlack, tLo) : tLo;
  }
  double tHighest() const {
    return std::isfinite(t) ? std::min(t + kRelativeT * std::abs(t) + tSlack, tHi) : tHi;
  }
  // Hit in (tMin, tMax) under some rounding within the slack.
  bool mayHit(double tMin, double tMax) const {
    return margin >= -slack && tHighest() > tMin && tLowest() < tMax;
  }
  // Hit in (tMin, tMax) under every rounding within the slack.
  bool mustHit(double tMin, double tMax) const {
    return margin > slack && tLowest() > tMin && tHighest() < tMax;
  }
  // A float test of this triangle could have reported `tFound`.
  bool allows(double tFound) const { return tFound >= tLowest() && tFound <= tHighest(); }
};

namespace detail {
inline double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }
// Distance from the origin to the segment ab.
inline double segmentDistance(glm::dvec2 a, glm::dvec2 b) {
  glm::dvec2 ab = b - a;
  double len2 = glm::dot(ab, ab);
  double s = len2 > 0.0 ? std::clamp(-glm::dot(a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(a + s * ab);
}
}  // namespace detail

// The ray against triangle (v0, v1, v2) with alpha mask `alpha` (shared/bvh_trace.h kAlpha*).
inline Crossing crossing(const gpu::bvh_trace::TraceRay& ray, glm::vec3 v0, glm::vec3 v1,
                         glm::vec3 v2, uint32_t alpha = gpu::bvh_trace::kAlphaOpaque) {
  Crossing c;
  const glm::dvec3 o(ray.origin), d(ray.dir);
  const glm::dvec3 a[3] = {glm::dvec3(v0) - o, glm::dvec3(v1) - o, glm::dvec3(v2) - o};
  const double dLen = glm::length(d);
  if (!(dLen > 0.0) || alpha == gpu::bvh_trace::kAlphaCutAll) return c;
  c.slack = kRoundingSlack * std::max({glm::length(a[0]), glm::length(a[1]), glm::length(a[2])});
  // Depths in units of dir as the watertight test has them: a[kz] / dir[kz], kz the ray's
  // dominant axis (the vertex's depth where the plane of constant kz through it crosses the
  // ray), not the orthogonal depth dot(a, dir) / |dir|^2. Both give the plane's exact t when
  // interpolated, but the test interpolates these with the weights of its float edge functions,
  // and on a sliver the ray grazes those weights can be anything in the simplex: t can then be
  // anywhere between the least and greatest of these depths, which a sliver's orthogonal depths
  // may not span (NVIDIA gave t 1.0173 on huge_coordinates triangle 1375, whose orthogonal
  // depths end at 1.0155 and these at 1.0568). Each is a few ulps of |a| / |dir[kz]| off in
  // float (a subtraction, a division, a product), and t, a sum of same-signed terms over their
  // sum, a few more: widening by slack / |dir[kz]| (32 ulps) covers that.
  const int kz = bvh::ShearedRay(ray.origin, ray.dir).kz;
  const double dz = std::abs(d[kz]);
  double depth[3];
  for (int i = 0; i < 3; ++i) depth[i] = a[i][kz] / d[kz];
  const double depthLo = std::min({depth[0], depth[1], depth[2]}), depthHi = std::max({depth[0], depth[1], depth[2]});
  c.tLo = depthLo - c.slack / dz;
  c.tHi = depthHi + c.slack / dz;
  // Across the ray: project onto a frame perpendicular to it (Duff et al. 2017).
  const glm::dvec3 z = d / dLen;
  const double sign = std::copysign(1.0, z.z), e = -1.0 / (sign + z.z), f = z.x * z.y * e;
  const glm::dvec3 bx(1.0 + sign * z.x * z.x * e, sign * f, -sign * z.x), by(f, sign + z.y * z.y * e, -z.y);
  glm::dvec2 p[3];
  for (int i = 0; i < 3; ++i) p[i] = {glm::dot(a[i], bx), glm::dot(a[i], by)};
  // Edge functions: w[i], twice the signed area opposite vertex i seen from the ray, is the
  // weight of v_i times twice the projected area. Moving the vertices by slack moves w[i] by at
  // most slack * (|p_j| + |p_k|).
  const double w[3] = {detail::cross2(p[1], p[2]), detail::cross2(p[2], p[0]), detail::cross2(p[0], p[1])};
  const double area = w[0] + w[1] + w[2];
  const double wSlack = 2.0 * c.slack * (glm::length(p[0]) + glm::length(p[1]) + glm::length(p[2]));
  if (area != 0.0) {
    c.t = (w[0] * depth[0] + w[1] * depth[1] + w[2] * depth[2]) / area;
    c.tSlack = c.slack / dz + wSlack / std::abs(area) * (depthHi - depthLo);
  }
  const bool inside = area != 0.0 && ((w[0] >= 0 && w[1] >= 0 && w[2] >= 0) || (w[0] <= 0 && w[1] <= 0 && w[2] <= 0));
  const double edges = std::min({detail::segmentDistance(p[0], p[1]), detail::segmentDistance(p[1], p[2]),
                                 detail::segmentDistance(p[2], p[0])});
  c.margin = inside ? edges : -edges;
  if (alpha == gpu::bvh_trace::kAlphaCutNearV0 && area != 0.0) {
    // Visible where the weight of v0 is at most 0.5: the cut is the line halfway from v0 to the
    // opposite edge, `height` the distance between those two.
    const double height = std::abs(area) / std::max(glm::length(p[2] - p[1]), 1e-300);
    c.margin = std::min(c.margin, (0.5 - w[0] / area) * height);
  }
  return c;
}

inline Crossing crossing(const bvh::SyntheticMesh& m, const gpu::bvh_trace::TraceRay& ray,
                         uint32_t triangle, const std::vector<uint32_t>* mask) {
  const auto& t = m.triangles[triangle];
  return crossing(ray, m.vertices[t.v0].position, m.vertices[t.v1].position, m.vertices[t.v2].position,
                  mask ? (*mask)[triangle] : gpu::bvh_trace::kAlphaOpaque);
}

enum class Verdict { Match, NearTie, Wrong };

// The device's closest hit `got` on `ray` against the brute-force loop's `ref` (the same mesh
// and mask). Match: the same triangle at t within kRelativeT (or both miss). NearTie: otherwise,
// but right under some rounding: `got`'s triangle may be hit at got.t, and no triangle that
// must be hit lies surely in front of it (for a miss: no triangle must be hit at all). So the
// device may take a neighbour across an edge the ray grazes, pass a silhouette the loop hit or
// hit one it passed, or place a hit on an ill-conditioned triangle (a grazing ray, a sliver)
// at another t, and nothing else.
inline Verdict judgeClosest(const bvh::SyntheticMesh& m, const gpu::bvh_trace::TraceRay& ray,
                            const gpu::bvh_trace::TraceHit& ref, const gpu::bvh_trace::TraceHit& got,
                            const std::vector<uint32_t>* mask = nullptr) {
  using gpu::bvh_trace::kNoHit;
  if (got.triangle == ref.triangle &&
      (ref.triangle == kNoHit || std::abs(got.t - ref.t) <= float(kRelativeT) * std::abs(ref.t)))
    return Verdict::Match;
  double front = std::numeric_limits<double>::infinity();
  if (got.triangle != kNoHit) {
    if (got.triangle >= m.triangles.size() || !(got.t > ray.tMin && got.t < ray.tMax)) return Verdict::Wrong;
    const Crossing c = crossing(m, ray, got.triangle, mask);
    if (!c.mayHit(ray.tMin, ray.tMax) || !c.allows(got.t)) return Verdict::Wrong;
    front = got.t;
  }
  for (uint32_t i = 0; i < m.triangles.size(); ++i) {
    const Crossing c = crossing(m, ray, i, mask);
    if (c.mustHit(ray.tMin, ray.tMax) && c.tHighest() < front) return Verdict::Wrong;
  }
  return Verdict::NearTie;
}

// The device's occlusion answer `got` (any-hit) on `ray` against the loop's `ref`. NearTie: they
// differ, but the device says occluded and some triangle may be hit in (tMin, tMax), or it says
// free and no triangle must be hit there (a graze, or a hit at tMax).
inline Verdict judgeOccluded(const bvh::SyntheticMesh& m, const gpu::bvh_trace::TraceRay& ray, bool ref,
                             bool got, const std::vector<uint32_t>* mask = nullptr) {
  if (ref == got) return Verdict::Match;
  for (uint32_t i = 0; i < m.triangles.size(); ++i) {
    const Crossing c = crossing(m, ray, i, mask);
    if (got && c.mayHit(ray.tMin, ray.tMax)) return Verdict::NearTie;
    if (!got && c.mustHit(ray.tMin, ray.tMax)) return Verdict::Wrong;
  }
  return got ? Verdict::Wrong : Verdict::NearTie;
}

// The most near-ties a comparison of `rays` rays accepts.
inline size_t nearTieBudget(size_t rays) { return size_t(std::ceil(kNearTieShare * double(rays))); }

}  // namespace osr::test
