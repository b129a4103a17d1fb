// Generated meshes for the BVH tests and benchmarks: tessellated surfaces (coherent, like real
// scenes) and random triangle soups (stress cases: degenerate, huge and tiny coordinates).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/scene.h"

namespace osr::bvh {

struct SyntheticMesh {
  std::vector<gpu::scene::Vertex> vertices;
  std::vector<gpu::scene::Triangle> triangles;
  void append(const SyntheticMesh& other);
};

// UV sphere with `segments` x `rings` quads (2 triangles each), radially displaced by a smooth
// bump pattern of relative height `bumps` (0 for a plain sphere).
SyntheticMesh makeSphere(glm::vec3 center, float radius, uint32_t segments, uint32_t rings,
                         float bumps = 0.0f);
// `count` random triangles whose vertices lie within `size` of a centre uniform in the cube
// [-extent, extent]^3 around `center`. degenerateEvery > 0 makes every n-th one degenerate
// (alternately collapsed to a point and to a line).
SyntheticMesh makeSoup(uint32_t count, uint32_t seed, glm::vec3 center, float extent, float size,
                       uint32_t degenerateEvery = 0);

}  // namespace osr::bvh
