// Test helpers for the OSR suites: load a scene file, build its BVH, render OSR passes.
#pragma once
#include <string>

#include "bvh/bvh.h"
#include "common/vk_test.h"
#include "osr/osr_integrator.h"
#include "pt/path_integrator.h"
#include "pt/gltf_writer.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"

namespace osr::test {

struct LoadedScene {
  scene::Scene scene;
  scene::Camera camera;
  std::unique_ptr<scene::GpuScene> gpu;
  bvh::Bvh bvh;
};

inline LoadedScene loadForTest(const std::string& path, float aspect = 1.f) {
  auto& ctx = context();
  LoadedScene s;
  s.scene = scene::loadScene(path);
  s.camera = scene::selectCamera(s.scene, "", aspect);
  s.gpu = std::make_unique<scene::GpuScene>(ctx, s.scene);
  s.bvh = bvh::buildGpu(ctx, s.gpu->vertices, s.gpu->triangles, s.gpu->triangleCount);
  return s;
}

// A closed 2 m box (inside -1..1) whose walls all emit radiance 1 and reflect diffusely with
// albedo 0.5, a camera inside: radiance is 1 / (1 - 0.5) = 2 everywhere, of which 1 arrives
// after at least one bounce. Written under the test's scratch folder `tag`; returns the path.
inline std::string writeEmissiveFurnace(const std::string& tag) {
  GltfWriter g;
  auto m = GltfWriter::diffuse(glm::vec3(0.5f));
  m["emissiveFactor"] = {1.0, 1.0, 1.0};
  int wall = g.material(m);
  glm::vec3 c[8];
  for (int i = 0; i < 8; ++i) c[i] = glm::vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& f : faces) g.quad(c[f[0]], c[f[1]], c[f[2]], c[f[3]], wall);
  g.camera({0.2f, -0.1f, 0.3f}, {0.5f, -0.6f, -1.f}, 1.2f);
  std::string path = (tempDir(tag) / "furnace.gltf").string();
  g.write(path);
  return path;
}

// The path tracer's image of the scene's camera, size x size pixels (the reference OSR tests
// compare against).
inline render::FilmLayers pathTrace(const LoadedScene& s, uint32_t size, uint32_t spp,
                                    uint32_t seed = 3) {
  pt::RenderSettings rs;
  rs.width = rs.height = size;
  rs.spp = spp;
  rs.seed = seed;
  return pt::render(context(), *s.gpu, s.bvh, s.camera, rs);
}

// Renders `passes` OSR passes, one submission each, and resolves the film.
inline render::FilmLayers renderOsrPasses(oneshot::OsrIntegrator& osr, const LoadedScene& s,
                                          uint32_t passes, uint32_t seed = 1) {
  auto& ctx = context();
  osr.restart(s.camera, seed);
  for (uint32_t k = 0; k < passes; ++k)
    ctx.submitAndWait([&](VkCommandBuffer cmd) { osr.record(cmd, k, 1, nullptr); });
  return osr.resolve();
}

}  // namespace osr::test
