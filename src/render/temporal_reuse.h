// Temporal reuse for a shot's frames (film_temporal.comp, docs/animation.md "Temporal reuse"):
// each frame's film is blended with the frames before it where they saw the same surface, so
// a camera path through a still scene gathers samples over frames, as a world-space cache
// would, on every pixel and for every mode. The history is the previous frame's blended film;
// each frame counts it for at most `maxHistory` times its own samples, so a frame's estimate
// holds about (1 + maxHistory) frames' samples and light from frames long gone fades out;
// under a camera that did not move, every frame before counts in full. History that is not
// consistent with the frame's neighbourhood is dropped. The frames must draw independent
// samples (osr-vk --frames gives each its own seed).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "render/film.h"
#include "shaders/shared/camera.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace osr::render {

// What a shot's frames do by default (--temporal-reuse): measured in docs/animation.md.
inline constexpr float kDefaultTemporalHistory = 3.0f;

class TemporalReuse {
 public:
  // Throws DeviceError when one vec4 layer of width x height does not fit a storage binding.
  TemporalReuse(const vk::Context& ctx, uint32_t width, uint32_t height, float maxHistory);
  // Blends the history into the film's combined, direct, indirect colour and variance (the
  // albedo, normal and depth stay the frame's), then keeps the result as the next frame's
  // history. `camera`: the frame's (render::makeFrame). A film of another size is refused.
  void apply(FilmLayers& film, const gpu::camera::CameraFrame& camera);
  // Drops the history: the scene changed, not only the camera (a moved mesh or light).
  void forget() { hasHistory_ = false; }
  // Share of the last frame's pixels that took history.
  double reusedShare() const { return reusedShare_; }
  // Wall seconds of the last apply (uploads, the pass, downloads).
  double lastSeconds() const { return lastSeconds_; }

  // The history after frame `frame` as bytes (its layers in float32 and the camera behind
  // it), with `key` naming what made it (the scene and settings), for a shot that is stopped
  // and resumed to continue bit for bit; empty without history.
  std::vector<uint8_t> save(int frame, uint64_t key) const;
  // Takes the history in `bytes` if it is the one after `frame` with this key and size
  // (returns true); otherwise leaves the state as it is.
  bool restore(const std::vector<uint8_t>& bytes, int frame, uint64_t key);

 private:
  struct Layers {
    vk::Buffer combined, direct, indirect, albedo, normal;
    std::array<vk::Buffer*, 5> all() { return {&combined, &direct, &indirect, &albedo, &normal}; }
    std::array<const vk::Buffer*, 5> all() const {
      return {&combined, &direct, &indirect, &albedo, &normal};
    }
  };
  const vk::Context& ctx_;
  uint32_t width_, height_;
  float maxHistory_;
  vk::ComputePipeline pipeline_;
  std::array<Layers, 2> layers_;  // the frame's and the history, swapping each frame
  uint32_t current_ = 0;
  vk::Buffer frameColour_;        // the frame's combined colour before the blend
  vk::Buffer cameras_;            // gpu::temporal::TemporalCameras
  gpu::camera::CameraFrame previousCamera_{};
  bool hasHistory_ = false;
  double reusedShare_ = 0.0;
  double lastSeconds_ = 0.0;
};

}  // namespace osr::render
