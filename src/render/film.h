// The film: per-pixel running sums written by pt_trace.comp (gpu::film::FilmPixel), and their
// resolution into averaged layers on the host.
#pragma once
#include <cstdint>
#include <vector>

#include "shaders/shared/film.h"
#include "vk/buffer.h"

namespace osr::render {

// Averaged film layers, interleaved, row-major with row 0 at the top of the image.
struct FilmLayers {
  int width = 0;
  int height = 0;
  uint32_t samples = 0;         // samples per pixel accumulated
  uint64_t droppedSamples = 0;  // non-finite path samples discarded (expected 0)
  std::vector<float> combined, direct, indirect, albedo, normal;  // RGB / XYZ
  std::vector<float> depth;  // view-axis distance of the first hit; 0 where no sample hit
};

class Film {
 public:
  Film(const vk::Context& ctx, uint32_t width, uint32_t height);
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  uint32_t pixelCount() const { return width_ * height_; }
  const vk::Buffer& buffer() const { return buffer_; }

  // Zeroes the sums (recorded: transfer then a barrier).
  void recordClear(VkCommandBuffer cmd) const;
  // Downloads and divides by the sample count.
  FilmLayers resolve() const;

 private:
  uint32_t width_, height_;
  vk::Buffer buffer_;
};

}  // namespace osr::render
