// Scenes of `osr-bench bvh` and `osr-bench trace`: a generated mesh of over a million triangles
// and the reference scenes, each with a camera for primary rays.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/args.h"
#include "bvh/gpu_builder.h"
#include "bvh/synthetic_mesh.h"
#include "scene/scene.h"

namespace osr::bench {

struct BvhBenchScene {
  std::string name;
  bvh::SyntheticMesh mesh;
  glm::mat4 worldFromCamera{1.0f};
  float yfov = 0.8f;
};

// `only` empty: all scenes; else the one with that name (InputError when unknown). triangles > 0
// instead gives one scene, "sphere_<N>": a displaced sphere of at least that many triangles
// (for scale: memory per triangle, scenes past one binding).
std::vector<BvhBenchScene> bvhBenchScenes(const std::string& only, uint32_t triangles = 0);

// The options of how the hierarchy is made, into `options`: --hierarchy (auto, lbvh or ploc;
// absent: auto), --ploc-local-rounds (0 to 4) and --ploc-tail-clusters (0 to kPlocTailCapacity;
// absent: the builder's defaults); InputError
// naming the benchmark.
void hierarchyOptions(app::Args& args, const std::string& bench, bvh::GpuBuildOptions& options);

// Peak resident memory of the process so far, in bytes (on lavapipe it includes device memory).
uint64_t peakRssBytes();

// CPU time of the whole process (every thread: lavapipe's workers, Embree's) in ms. On a
// machine shared with other jobs, wall time swings with their load; the CPU time a phase
// consumes does much less, so the benchmarks report both.
double processCpuMs();

}  // namespace osr::bench
