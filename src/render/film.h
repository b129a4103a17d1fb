// The film: per-pixel running sums written by pt_trace.comp (gpu::film::FilmPixel), and their
// resolution into averaged layers on the host.
//
// A film may be larger than one storage-buffer binding (lavapipe's maxStorageBufferRange is
// 128 MiB, 1.4 Mpx of 96-byte pixels; 3840 x 2160 needs 760 MiB): passes bind it in windows
// of consecutive pixels, window(first, count), and index their window from 0. The buffer
// itself is one allocation, so its limit is maxMemoryAllocationSize (2 GiB on lavapipe).
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
  uint32_t samples = 0;         // samples per pixel accumulated (OSR: its passes)
  uint64_t droppedSamples = 0;  // non-finite path samples discarded (expected 0)
  std::vector<float> combined, direct, indirect, albedo, normal;  // RGB / XYZ
  std::vector<float> depth;  // view-axis distance of the first hit; 0 where no sample hit
  // Variance of each pixel's luminance estimate: with n > 1 samples the sample variance over
  // n, (sum L^2 - n mean^2) / (n (n - 1)); with one sample's worth (OSR) what its resolve
  // stored (film.h); 0 where unknown.
  std::vector<float> variance;
  // Share of each pixel's camera rays that saw light directly (an emitter or the environment):
  // pixels the denoisers keep as they are and out of their neighbours' averages.
  std::vector<float> light;
  // The colour before denoising, when a denoiser replaced `combined` (render/denoiser.h).
  std::vector<float> noisy;

  // Sizes every layer but `noisy` for width x height (zeroed where it grows). A front end
  // with a deadline calls it before rendering: at 4K the layers are 560 MiB, and their first
  // touch costs seconds on a CPU device, which then count against the set-up, not the end.
  void allocate(int width, int height);
};

// Sets each pixel's variance to the spread of one sample's luminance over its 3 x 3
// neighbourhood: a film of one sample per pixel has no per-pixel estimate (Film::resolve
// gives 0), and with 0 the denoisers' luminance weights would keep every pixel as it is.
// SVGF estimates the variance spatially the same way while a pixel's history is short.
void estimateVarianceFromNeighbours(FilmLayers& film);

// `from` resized to `into`'s width x height (set by the caller; every layer is sized here) by
// bilinear interpolation between pixel centres (colour layers as x / (1 + x), so a lamp does not
// spread over its neighbours, though its own pixels keep only part of its radiance; the others
// as they are; normals are not renormalised; `noisy` only where `from` has one). The viewer shows a coarse film this way
// until the full-resolution one has a sample.
void upsampleBilinear(const FilmLayers& from, FilmLayers& into);

// Pixel windows start at multiples of this many pixels, so that a window's byte offset is a
// multiple of 256, the largest minStorageBufferOffsetAlignment Vulkan allows, for any pixel
// struct whose size is a multiple of 16 bytes (std430 vec4 rows).
inline constexpr uint32_t kWindowAlignPixels = 256;

// A film layer (rgb, interleaved) with a fourth value per pixel from `w` (0 where `w` is
// empty) as the passes over a film's layers bind it: a vec4 per pixel.
std::vector<float> vec4Layer(const std::vector<float>& rgb, const std::vector<float>& w);
// Such a layer's rgb into `rgb`, and its fourth values into `w` if given (both sized).
void fromVec4Layer(const std::vector<float>& layer, std::vector<float>& rgb,
                   std::vector<float>* w = nullptr);

// Bytes of one image layer of a vec4 per pixel (the denoisers', temporal reuse's), which a
// pass binds whole. Throws DeviceError ("<what>: a WxH layer needs ...") when that is over the
// device's maxStorageBufferRange.
uint64_t wholeLayerBytes(const vk::Context& ctx, uint32_t width, uint32_t height, const char* what);

// The most pixels of bytesPerPixel one binding can cover on this device: a multiple of
// kWindowAlignPixels (at least one). Throws DeviceError if not even that fits.
uint32_t windowPixels(const vk::Context& ctx, uint64_t bytesPerPixel);

class Film {
 public:
  Film(const vk::Context& ctx, uint32_t width, uint32_t height);
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  uint32_t pixelCount() const { return width_ * height_; }
  const vk::Buffer& buffer() const { return buffer_; }
  // Pixels [first, first + count) as one binding: count <= windowPixels(ctx,
  // sizeof(FilmPixel)), first a multiple of kWindowAlignPixels.
  vk::BufferRange window(uint32_t first, uint32_t count) const;

  // Zeroes the sums (recorded: transfer then a barrier).
  void recordClear(VkCommandBuffer cmd) const;
  // Downloads and divides by the sample count, into `out` (sized by FilmLayers::allocate;
  // `noisy` emptied).
  void resolve(FilmLayers& out) const;
  FilmLayers resolve() const;

 private:
  uint32_t width_, height_;
  vk::Buffer buffer_;
};

}  // namespace osr::render
