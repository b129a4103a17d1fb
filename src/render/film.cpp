#include "render/film.h"

#include "common/error.h"

namespace osr::render {



Film::Film(const vk::Context& ctx, uint32_t width, uint32_t height)
    : width_(width), height_(height) {
  const uint64_t bytes = uint64_t(width) * height * sizeof(gpu::film::FilmPixel);
  // One binding covers the whole film: refuse rather than truncate past the device limit.
  // A device limit, not bad input (the same size fits a device with a larger range): exit 1.
  if (bytes > ctx.caps().maxStorageBufferRange)
    throw DeviceError("film: " + std::to_string(width) + "x" + std::to_string(height) + " needs " +
                     std::to_string(bytes >> 20) +
                     " MiB, over the device's maxStorageBufferRange of " +
                     std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB");
  buffer_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "pt film");
}

void Film::recordClear(VkCommandBuffer cmd) const {
  vkCmdFillBuffer(cmd, buffer_.handle(), 0, VK_WHOLE_SIZE, 0u);
  vk::transferBarrier(cmd);
}

FilmLayers Film::resolve() const {
  auto px = buffer_.downloadVector<gpu::film::FilmPixel>(pixelCount());
  FilmLayers out;
  out.width = int(width_);
  out.height = int(height_);
  const size_t n = px.size();
  for (auto* v : {&out.combined, &out.direct, &out.indirect, &out.albedo, &out.normal})
    v->resize(n * 3);
  out.depth.resize(n);
  out.samples = n ? uint32_t(px[0].combined.w + 0.5f) : 0;
  for (size_t i = 0; i < n; ++i) {
    const gpu::film::FilmPixel& p = px[i];
    const float inv = p.combined.w > 0.f ? 1.f / p.combined.w : 0.f;
    for (int c = 0; c < 3; ++c) {
      out.combined[i * 3 + c] = p.combined[c] * inv;
      out.direct[i * 3 + c] = p.direct[c] * inv;
      out.indirect[i * 3 + c] = p.indirect[c] * inv;
      out.albedo[i * 3 + c] = p.albedo[c] * inv;
      out.normal[i * 3 + c] = p.normal[c] * inv;
    }
    out.depth[i] = p.depth.y > 0.f ? p.depth.x / p.depth.y : 0.f;
    out.droppedSamples += uint64_t(p.normal.w);
  }
  return out;
}

}  // namespace osr::render
