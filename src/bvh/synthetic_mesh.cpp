#include "bvh/synthetic_mesh.h"

#include <cmath>
#include <random>

namespace osr::bvh {

void SyntheticMesh::append(const SyntheticMesh& other) {
  uint32_t base = static_cast<uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (auto t : other.triangles) triangles.push_back({t.v0 + base, t.v1 + base, t.v2 + base, t.material});
}

SyntheticMesh makeSphere(glm::vec3 center, float radius, uint32_t segments, uint32_t rings,
                         float bumps) {
  SyntheticMesh m;
  const float kPi = 3.14159265358979f;
  for (uint32_t r = 0; r <= rings; ++r) {
    float theta = kPi * r / rings;
    for (uint32_t s = 0; s <= segments; ++s) {
      float phi = 2.0f * kPi * s / segments;
      glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      float h = 1.0f + bumps * std::sin(7.0f * phi) * std::sin(5.0f * theta) * std::sin(3.0f * phi + theta);
      gpu::scene::Vertex v{};
      v.position = center + radius * h * n;
      v.normal = n;
      v.u = float(s) / segments;
      v.v = float(r) / rings;
      m.vertices.push_back(v);
    }
  }
  for (uint32_t r = 0; r < rings; ++r)
    for (uint32_t s = 0; s < segments; ++s) {
      uint32_t i0 = r * (segments + 1) + s, i1 = i0 + 1, i2 = i0 + segments + 1, i3 = i2 + 1;
      m.triangles.push_back({i0, i2, i1, 0});
      m.triangles.push_back({i1, i2, i3, 0});
    }
  return m;
}

SyntheticMesh makeSoup(uint32_t count, uint32_t seed, glm::vec3 center, float extent, float size,
                       uint32_t degenerateEvery) {
  SyntheticMesh m;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto rand3 = [&] { return glm::vec3(u(rng), u(rng), u(rng)); };
  for (uint32_t i = 0; i < count; ++i) {
    glm::vec3 c = center + extent * rand3();
    glm::vec3 p[3] = {c + size * rand3(), c + size * rand3(), c + size * rand3()};
    if (degenerateEvery && i % degenerateEvery == 0) {
      if ((i / degenerateEvery) % 2 == 0)
        p[1] = p[2] = p[0];                    // a point
      else
        p[2] = 0.5f * (p[0] + p[1]);           // a line
    }
    uint32_t base = static_cast<uint32_t>(m.vertices.size());
    for (const auto& q : p) {
      gpu::scene::Vertex v{};
      v.position = q;
      v.normal = glm::vec3(0, 0, 1);
      m.vertices.push_back(v);
    }
    m.triangles.push_back({base, base + 1, base + 2, 0});
  }
  return m;
}

}  // namespace osr::bvh
