#include "bvh/host_trace.h"

#include <algorithm>
#include <cstring>

#include "bvh/ray_triangle.h"

namespace osr::bvh {

namespace {
using gpu::bvh::kBvhLeafCountMask;
using gpu::bvh::kBvhLeafCountShift;
using gpu::bvh::kBvhLeafFirstMask;
using gpu::bvh::kBvhLeafFlag;

bool hitBox(const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& origin,
            const glm::vec3& inv, float tMin, float tFar, float& tEnter) {
  glm::vec3 t0 = (lo - origin) * inv, t1 = (hi - origin) * inv;
  glm::vec3 a = glm::min(t0, t1), b = glm::max(t0, t1);
  tEnter = std::max(std::max(a.x, a.y), std::max(a.z, tMin));
  float tExit = std::min(std::min(b.x, b.y), std::min(b.z, tFar)) * 1.00000036f;
  return tEnter <= tExit;
}
}  // namespace

gpu::bvh_trace::TraceHit HostTracer::closest(const gpu::bvh_trace::TraceRay& ray) const {
  gpu::bvh_trace::TraceHit hit{ray.tMax, gpu::bvh_trace::kNoHit, glm::vec2(0)};
  ShearedRay r(ray.origin, ray.dir);
  glm::vec3 safe = ray.dir;
  for (int k = 0; k < 3; ++k)
    if (std::abs(safe[k]) < 1e-30f) safe[k] = safe[k] < 0 ? -1e-30f : 1e-30f;
  glm::vec3 inv = 1.0f / safe;
  float tFar = ray.tMax;
  uint32_t stack[gpu::bvh::kBvhMaxDepth];
  uint32_t sp = 0, node = 0;
  for (;;) {
    const auto& n = tree_.nodes[node];
    float ta, tb;
    bool ha = hitBox(n.aMin, n.aMax, ray.origin, inv, ray.tMin, tFar, ta);
    bool hb = hitBox(n.bMin, n.bMax, ray.origin, inv, ray.tMin, tFar, tb);
    for (int side = 0; side < 2; ++side) {
      uint32_t ref = side == 0 ? n.a : n.b;
      bool& entered = side == 0 ? ha : hb;
      if (!entered || !(ref & kBvhLeafFlag)) continue;
      entered = false;
      uint32_t first = ref & kBvhLeafFirstMask, count = (ref >> kBvhLeafCountShift) & kBvhLeafCountMask;
      for (uint32_t i = first; i < first + count; ++i) {
        const auto& tri = leaves_[i];
        float t;
        glm::vec2 bary;
        if (!intersectTriangle(r, glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2), ray.tMin, tFar, t, bary))
          continue;
        uint32_t id;
        std::memcpy(&id, &tri.v0.w, 4);
        hit = {t, id, bary};
        tFar = t;
      }
    }
    if (ha && hb) {
      stack[sp++] = ta <= tb ? n.b : n.a;
      node = ta <= tb ? n.a : n.b;
    } else if (ha) {
      node = n.a;
    } else if (hb) {
      node = n.b;
    } else {
      if (sp == 0) break;
      node = stack[--sp];
    }
  }
  return hit;
}

}  // namespace osr::bvh
