// Axis-aligned box on the host, shared by the CPU builder, tree inspection and the benchmarks.
#pragma once
#include <glm/glm.hpp>
#include <limits>

namespace osr::bvh {

struct Aabb {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};

  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  // Surface area; 0 for an empty box.
  float area() const {
    if (empty()) return 0.0f;
    glm::vec3 d = hi - lo;
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
  bool contains(const Aabb& b) const {
    return b.empty() || (glm::all(glm::lessThanEqual(lo, b.lo)) &&
                         glm::all(glm::greaterThanEqual(hi, b.hi)));
  }
};

}  // namespace osr::bvh
