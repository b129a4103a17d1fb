#include "osr/map_tracer.h"

#include <algorithm>

#include "common/error.h"
#include "osr/osr_integrator.h"
#include "render/camera_frame.h"

namespace osr::oneshot {

namespace o = gpu::osr;

MapTracer::MapTracer(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
                     const scene::Camera& camera, uint32_t width, uint32_t height, uint32_t seed)
    : ctx_(ctx),
      width_(width),
      height_(height),
      film_(ctx, width, height),
      buffers_(ctx, width, height, kChunkMaps, kChunkMaps),
      gbuffer_(ctx, scene.features, scene.texelFetch),
      maps_(ctx, scene.features, scene.texelFetch),
      cache_(ctx, o::kMapCacheWays),
      bindings_{&buffers_, &film_, &bvh, &scene, &cache_} {
  gbuffer_.prepare(bvh);
  maps_.prepare(bvh);
  auto frame = render::makeFrame(camera, width, height, seed);
  buffers_.frame.upload(&frame, sizeof frame);
  setView(0);
}

void MapTracer::setView(uint32_t view) {
  view_ = view;
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, buffers_.accum.handle(), 0, VK_WHOLE_SIZE, 0u);
    vk::transferBarrier(cmd);
    // One camera ray; the direct layer is not read.
    gbuffer_.record(cmd, bindings_, {view, 0, 0.0f, {0, width_ * height_}});
  });
}

std::vector<float> MapTracer::trace(const std::vector<glm::uvec2>& pixels, uint32_t pathsPerTexel,
                                    uint32_t stream) {
  const size_t mapFloats = size_t(o::kMapChannels) * gpu::hemi::kMapTexels;
  std::vector<float> out(pixels.size() * mapFloats);
  for (size_t first = 0; first < pixels.size(); first += kChunkMaps) {
    const uint32_t count = uint32_t(std::min<size_t>(kChunkMaps, pixels.size() - first));
    std::vector<o::MapPoint> points(count);
    for (uint32_t i = 0; i < count; ++i) {
      const glm::uvec2 p = pixels[first + i];
      if (p.x >= width_ || p.y >= height_)
        throw InputError("maps: pixel (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                         ") is outside the " + std::to_string(width_) + "x" +
                         std::to_string(height_) + " image");
      points[i].pixel = glm::uvec4(p, 0u, 0u);
    }
    buffers_.mapPoints.uploadVector(points);
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      // A grid of radius 0: the maps sit at the pixels of their points.
      maps_.record(cmd, bindings_, {o::MapGrid{}, stream, {0, count}, pathsPerTexel});
    });
    buffers_.oneShot.download(out.data() + first * mapFloats, count * mapFloats * sizeof(float));
  }
  return out;
}

std::vector<o::GBufferPixel> MapTracer::gbuffer() const {
  return buffers_.gbuffer.downloadVector<o::GBufferPixel>(size_t(width_) * height_);
}

}  // namespace osr::oneshot
