// Hemisphere maps at chosen pixels of a view, on the OSR integrator's own passes (osr_gbuffer
// then osr_maps), for datasets and tests: the one-shot input the renderer feeds its network
// and, with many paths per texel, reference maps of the same points. Maps are
// [7][32][32] float (radiance RGB, hit normal XYZ in the map frame, distance), DESIGN.md
// "Hemisphere maps".
#pragma once
#include <glm/glm.hpp>
#include <vector>

#include "bvh/bvh.h"
#include "osr/osr_buffers.h"
#include "osr/osr_passes.h"
#include "scene/scene.h"
#include "scene_gpu/gpu_scene.h"

namespace osr::oneshot {

class MapTracer {
 public:
  MapTracer(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
            const scene::Camera& camera, uint32_t width, uint32_t height, uint32_t seed);

  // Finds the first non-specular surface through each pixel's centre region (jittered by
  // `view`, which selects the G-buffer's random stream); later trace() calls use it.
  void setView(uint32_t view);
  // Traces maps at `pixels` (x < width, y < height) with pathsPerTexel paths per texel; the
  // random stream is selected by `stream`, so two calls with different streams give
  // independent maps of the same points. Returns maps x 7 x 32 x 32 floats; a pixel whose
  // G-buffer found no surface gives radiance 0, normal 0, distance -1.
  std::vector<float> trace(const std::vector<glm::uvec2>& pixels, uint32_t pathsPerTexel,
                           uint32_t stream);
  // The G-buffer surfaces at the last view (position.w: 1 where there is one).
  std::vector<gpu::osr::GBufferPixel> gbuffer() const;

  static constexpr uint32_t kChunkMaps = 256;

 private:
  const vk::Context& ctx_;
  uint32_t width_, height_, view_ = 0;
  render::Film film_;
  OsrBuffers buffers_;
  GBufferPass gbuffer_;
  MapsPass maps_;
  MapCache cache_;  // unused (no lookups): the passes bind its buffers all the same
  OsrBindings bindings_;
};

}  // namespace osr::oneshot
