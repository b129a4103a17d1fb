// A render of ours against a Cycles reference with our own noise taken out: two renders with
// different seeds give the mean M = (A + B) / 2 and an unbiased estimate of M's noise term in
// relMSE, sum (A - B)^2 / (4 (ref^2 + eps)) / n, so that relMSE - noise is the difference of
// what the two renderers compute (plus the reference's own noise).
#pragma once

#include <cstdio>
#include <string>

#include "bvh/bvh.h"
#include "common/vk_test.h"
#include "image/image_metrics.h"
#include "pt/path_integrator.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"

namespace osr::test {

struct CyclesComparison {
  double relmse = 0, noise = 0, lumRatio = 0;
};

// `scenePath` rendered by `settings` (with seeds firstSeed and firstSeed + 1)
// against `ref`, which has the settings' size; prints one line naming `label`.
inline CyclesComparison compareTwoRenders(const std::string& label, const std::string& scenePath,
                                          pt::RenderSettings settings, const image::RgbImage& ref,
                                          uint32_t firstSeed) {
  auto& ctx = context();
  scene::Scene sc = scene::loadScene(scenePath);
  scene::Camera cam = scene::selectCamera(sc, "", 1.f);
  scene::GpuScene gs(ctx, sc);
  bvh::Bvh tree = bvh::buildGpu(ctx, gs.vertices, gs.triangles, gs.triangleCount);
  settings.seed = firstSeed;
  render::FilmLayers a = pt::render(ctx, gs, tree, cam, settings);
  settings.seed = firstSeed + 1;
  render::FilmLayers b = pt::render(ctx, gs, tree, cam, settings);
  image::RgbImage m{int(settings.width), int(settings.height), a.combined};
  double noise = 0;
  for (size_t i = 0; i < m.rgb.size(); ++i) {
    double d = double(a.combined[i]) - b.combined[i];
    noise += d * d / (4.0 * (double(ref.rgb[i]) * ref.rgb[i] + image::kRelMseEpsilon));
    m.rgb[i] = 0.5f * (a.combined[i] + b.combined[i]);
  }
  CyclesComparison c;
  c.noise = noise / double(m.rgb.size());
  c.relmse = image::relMse(m, ref);
  c.lumRatio = image::meanLuminance(m) / image::meanLuminance(ref);
  std::printf(
      "%s %ux%u, 2 x %u spp: relmse %.5f, estimated noise %.5f, relmse - noise %.5f, "
      "lum_ratio %.4f\n",
      label.c_str(), settings.width, settings.height, settings.spp, c.relmse, c.noise,
      c.relmse - c.noise, c.lumRatio);
  return c;
}

}  // namespace osr::test
