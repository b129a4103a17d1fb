#include "bench/bvh_scenes.h"

#include <sys/resource.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "common/error.h"

namespace osr::bench {

std::vector<BvhBenchScene> bvhBenchScenes(const std::string& only, uint32_t triangles) {
  std::vector<BvhBenchScene> out;
  if (triangles > 0) {
    // rings x 2 rings quads of 2 triangles: 4 rings^2 >= triangles.
    uint32_t rings = uint32_t(std::ceil(std::sqrt(triangles / 4.0)));
    BvhBenchScene s;
    s.mesh = bvh::makeSphere({0, 0, 0}, 1.0f, 2 * rings, rings, 0.15f);
    s.name = "sphere_" + std::to_string(s.mesh.triangles.size());
    // Outside, looking at the bumps.
    s.worldFromCamera = glm::inverse(glm::lookAt(glm::vec3(0.4f, 0.9f, 3.0f), glm::vec3(0), glm::vec3(0, 1, 0)));
    s.yfov = 0.8f;
    out.push_back(std::move(s));
    return out;
  }
  if (only.empty() || only == "generated_1m") {
    // A displaced sphere (1,000,000 triangles) around a cloud of 50,000 small triangles: long
    // thin triangles near the poles, a dense interior, and rays that cross both.
    BvhBenchScene s;
    s.name = "generated_1m";
    s.mesh = bvh::makeSphere({0, 0, 0}, 1.0f, 1000, 500, 0.15f);
    s.mesh.append(bvh::makeSoup(50000, 1, {0, 0, 0}, 0.5f, 0.02f));
    // Inside the sphere looking at the cloud, so primary rays hit both.
    s.worldFromCamera = glm::inverse(glm::lookAt(glm::vec3(0.1f, 0.2f, 0.9f), glm::vec3(0), glm::vec3(0, 1, 0)));
    s.yfov = 1.2f;
    out.push_back(std::move(s));
  }
  for (const char* name : {"cornell", "room"}) {
    if (!only.empty() && only != name) continue;
    std::string path = std::string(OSR_SOURCE_DIR) + "/scenes/" + name + "/" + name + ".gltf";
    scene::Scene sc = scene::loadScene(path);
    scene::Camera cam = scene::selectCamera(sc, "", 1.0f);
    BvhBenchScene s;
    s.name = name;
    s.mesh.vertices = std::move(sc.vertices);
    s.mesh.triangles = std::move(sc.triangles);
    s.worldFromCamera = cam.worldFromCamera;
    s.yfov = cam.yfov;
    out.push_back(std::move(s));
  }
  if (out.empty()) throw InputError("unknown scene '" + only + "' (generated_1m, cornell, room)");
  return out;
}

void hierarchyOptions(app::Args& args, const std::string& bench, bvh::GpuBuildOptions& options) {
  if (auto rounds = args.integer("--ploc-local-rounds", 0, 4)) options.plocLocalRounds = uint32_t(*rounds);
  if (auto clusters = args.integer("--ploc-tail-clusters", 0, gpu::bvh_build::kPlocTailCapacity))
    options.plocTailClusters = uint32_t(*clusters);
  const std::string h = args.value("--hierarchy").value_or("auto");
  if (h == "auto")
    options.hierarchy = bvh::Hierarchy::Auto;
  else if (h == "lbvh")
    options.hierarchy = bvh::Hierarchy::Lbvh;
  else if (h == "ploc")
    options.hierarchy = bvh::Hierarchy::Ploc;
  else
    throw InputError(bench + ": --hierarchy takes auto, lbvh or ploc, not '" + h + "'");
}

uint64_t peakRssBytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return uint64_t(usage.ru_maxrss) * 1024;  // kilobytes on Linux
}

double processCpuMs() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto ms = [](const timeval& t) { return t.tv_sec * 1e3 + t.tv_usec * 1e-3; };
  return ms(usage.ru_utime) + ms(usage.ru_stime);
}

}  // namespace osr::bench
