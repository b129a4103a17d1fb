// The image denoisers every mode applies to its film's combined colour (docs/denoise.md): the
// learned image U-Net (stage "image_denoiser", nn/image_unet.h) run in overlapping tiles, and
// the non-learned edge-aware a-trous filter of SVGF. Both read the film's first-hit albedo,
// normal and depth; the filter also its per-pixel variance. Compute passes on device buffers
// (render/denoise_passes.h); FilmLayers go up and the denoised colour comes down.
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "nn_kernels/image_unet.h"
#include "nn_kernels/weights.h"
#include "render/denoise_passes.h"
#include "render/film.h"
#include "vk/buffer.h"
#include "vk/timer.h"

namespace osr::render {

// The image layers as the denoise passes read them (shared/denoise.h), on the device.
class DenoiseImage {
 public:
  // Throws DeviceError when one layer of width x height does not fit a storage binding.
  DenoiseImage(const vk::Context& ctx, uint32_t width, uint32_t height);
  void upload(const FilmLayers& film);
  // rgb interleaved, row-major, of a vec4-per-pixel buffer of this size.
  std::vector<float> download(const vk::Buffer& pixels) const;
  DenoiseBindings bindings() const;
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  const vk::Context& context() const { return ctx_; }

 private:
  const vk::Context& ctx_;
  uint32_t width_, height_;
  vk::Buffer colour_, albedo_, normal_;
};

// A tile of the network's run: tile (x, y, w, h) of the padded image, and the core it writes.
struct DenoiseTile {
  uint32_t x, y, width, height;
  uint32_t coreX0, coreY0, coreX1, coreY1;
};

// The tiles covering a width x height image padded to multiples of 8: one tile when the
// padded image fits maxTile, else cores of maxTile - 2 margin with `margin` pixels of context
// each side (clipped at the image), origins multiples of 8.
std::vector<DenoiseTile> denoiseTiles(uint32_t width, uint32_t height, uint32_t maxTile, uint32_t margin);

// The network's tiles: its input from the image, the network, and its output back into the
// image, by colour (osr_image_unet_v1) or by the predicted kernels (osr_image_kpn_v1).
class NetworkDenoiser {
 public:
  // maxTile 0: the largest tile the device and `budget` allow (ImageUNet::maxTileFor), capped
  // at the padded image.
  NetworkDenoiser(const vk::Context& ctx, const nn::ImageUNetWeights& weights, uint32_t width,
                  uint32_t height, uint32_t maxTile = 0, uint64_t budget = 512ull << 20);
  // Records the denoised colour of `image` into `out` (vec4 per pixel, w = 0).
  void record(VkCommandBuffer cmd, const DenoiseImage& image, const vk::Buffer& out,
              vk::GpuTimer* timer = nullptr) const;
  const std::vector<DenoiseTile>& tiles() const { return tiles_; }

 private:
  uint32_t width_, height_;
  std::vector<DenoiseTile> tiles_;
  std::unique_ptr<nn::ImageUNet> net_;
  ExposurePass exposure_;
  NetInputPass input_;
  NetOutputPass output_;
  std::optional<KernelApplyPass> firstKernel_, middleKernel_, lastKernel_;
  vk::Buffer sums_, kernelPing_, kernelPong_;  // kernel levels' colour, one tile each

  void recordKernels(VkCommandBuffer cmd, DenoiseBindings b, gpu::denoise::DenoisePush push) const;
};

// SVGF's edge-aware a-trous wavelet filter: 5 iterations, steps 1, 2, 4, 8, 16.
struct AtrousSettings {
  float sigmaLuminance = 4.0f;  // SVGF's sigma_l
  float sigmaNormal = 128.0f;   // SVGF's sigma_n
  float sigmaDepth = 1.0f;      // SVGF's sigma_z
  uint32_t iterations = 5;
};

class AtrousFilter {
 public:
  AtrousFilter(const vk::Context& ctx, uint32_t width, uint32_t height, const AtrousSettings& settings = {});
  void record(VkCommandBuffer cmd, const DenoiseImage& image, const vk::Buffer& out) const;

 private:
  uint32_t width_, height_;
  AtrousSettings settings_;
  AtrousPass first_, middle_, last_, only_;
  vk::Buffer ping_, pong_;
};

// The front ends' switch (--network, --filter): which model, if any, and whether the filter
// runs when no network does. With both, the filter runs on films of fewer than
// kNetworkMinSamples samples per pixel and the network on the others.
struct DenoiseSettings {
  enum class Network { None, Default, File };
  Network network = Network::None;
  std::string networkFile;
  bool atrous = false;
  bool chosen = false;  // --network or --filter was given (else the mode's default)
  bool active() const { return network != Network::None || atrous; }
  // Reads the model it names, so that a bad file or a missing shipped model is refused before
  // any rendering: InputError "<file>: <problem>".
  void check() const;
};

// The model the executable carries (models/osr_image_denoiser.osrw), or none.
std::optional<nn::ImageUNetWeights> defaultImageModel();
inline constexpr char kDefaultImageModelName[] = "built-in model models/osr_image_denoiser.osrw";
// The fewest samples per pixel the network denoises when the filter is on too: at 1 sample the
// shipped network is worse than the filter, from 4 better (docs/training.md, "Image denoiser"),
// so the viewer's first images after a move are filtered.
inline constexpr uint32_t kNetworkMinSamples = 4;
// The samples per pixel of a film on which a timing probe runs every pass of the denoiser it
// times: the network (from kNetworkMinSamples) and the two convergence passes.
inline constexpr uint32_t kDenoiseProbeSamples = std::max(kNetworkMinSamples, gpu::denoise::kConvergeMinSamples);

class Denoiser {
 public:
  // Loads the model (InputError on a bad file or when `default` has no shipped model).
  Denoiser(const vk::Context& ctx, const DenoiseSettings& settings, uint32_t width, uint32_t height);
  // Replaces film.combined by the denoised colour and keeps the raw one in film.noisy; a film
  // already denoised is denoised again from its noisy colour. `unconverged`, if given and a
  // denoiser ran, gets the network's or filter's colour before the convergence passes (rgb
  // interleaved).
  void apply(FilmLayers& film, std::vector<float>* unconverged = nullptr);
  double lastSeconds() const { return lastSeconds_; }
  // What the last apply ran ("network", "atrous"); before the first, the network if there is one.
  const char* name() const;
  uint32_t width() const { return image_.width(); }
  uint32_t height() const { return image_.height(); }

 private:
  const vk::Context& ctx_;
  DenoiseSettings settings_;
  DenoiseImage image_;
  std::unique_ptr<NetworkDenoiser> network_;
  std::unique_ptr<AtrousFilter> filter_;
  BiasPass bias_;
  ConvergePass converge_;
  // The network's or filter's colour; after BiasPass; after ConvergePass.
  vk::Buffer denoised_, unbiased_, out_;
  double lastSeconds_ = 0;
  bool lastRanNetwork_ = true;
};

}  // namespace osr::render
