// Scenes of `osr-bench bvh` and `osr-bench trace`: a generated mesh of over a million triangles
// and the reference scenes, each with a camera for primary rays.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/synthetic_mesh.h"
#include "scene/scene.h"

namespace osr::bench {

struct BvhBenchScene {
  std::string name;
  bvh::SyntheticMesh mesh;
  glm::mat4 worldFromCamera{1.0f};
  float yfov = 0.8f;
};

// `only` empty: all scenes; else the one with that name (InputError when unknown).
std::vector<BvhBenchScene> bvhBenchScenes(const std::string& only);

}  // namespace osr::bench
