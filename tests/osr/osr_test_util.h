// Test helpers for the OSR suites: load a scene file, build its BVH, render OSR passes.
#pragma once
#include <string>

#include "bvh/bvh.h"
#include "common/vk_test.h"
#include "osr/osr_integrator.h"
#include "scene_gpu/gpu_scene.h"
#include "scene/scene.h"

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
