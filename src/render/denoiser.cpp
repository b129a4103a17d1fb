#include "render/denoiser.h"

#include <algorithm>
#include <chrono>

#include "common/error.h"
#include "nn_kernels/weights_format.h"
#include "render/default_image_model.h"

namespace osr::render {

namespace g = gpu::denoise;

namespace {

uint32_t padded(uint32_t size) { return (size + nn::kImageMultiple - 1) / nn::kImageMultiple * nn::kImageMultiple; }

g::DenoisePush imagePush(uint32_t width, uint32_t height) {
  g::DenoisePush p{};
  p.width = width;
  p.height = height;
  p.paddedWidth = padded(width);
  p.paddedHeight = padded(height);
  return p;
}

// Spans [start, end) of one axis and the core [core0, core1) each writes.
struct Span {
  uint32_t start, end, core0, core1;
};
std::vector<Span> spans(uint32_t size, uint32_t maxTile, uint32_t margin) {
  const uint32_t full = padded(size);
  if (full <= maxTile) return {{0, full, 0, size}};
  const uint32_t core = maxTile - 2 * margin;
  std::vector<Span> out;
  for (uint32_t c = 0; c < size; c += core)
    out.push_back({c > margin ? c - margin : 0, std::min(c + core + margin, full), c, std::min(c + core, size)});
  return out;
}

// Binds step i of a chain of n passes that each read b.colour and write b.out: the first reads
// the image, later ones the previous step's output; the last writes `out`, the others
// alternate between ping and pong.
void chainStep(DenoiseBindings& b, uint32_t i, uint32_t n, const vk::BufferRange& out, const vk::Buffer& ping,
               const vk::Buffer& pong) {
  if (i > 0) b.colour = (i % 2) ? ping : pong;
  b.out = i + 1 == n ? out : vk::BufferRange((i % 2) ? pong : ping);
}

}  // namespace

DenoiseImage::DenoiseImage(const vk::Context& ctx, uint32_t width, uint32_t height)
    : ctx_(ctx), width_(width), height_(height) {
  const uint64_t bytes = wholeLayerBytes(ctx, width, height, "denoiser");
  colour_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "denoise colour");
  albedo_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "denoise albedo");
  normal_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "denoise normal");
}

void DenoiseImage::upload(const FilmLayers& film) {
  if (film.width != int(width_) || film.height != int(height_))
    throw DeviceError("denoiser: film size does not match the denoiser's");
  colour_.uploadVector(vec4Layer(film.noisy.empty() ? film.combined : film.noisy, film.variance));
  albedo_.uploadVector(vec4Layer(film.albedo, film.depth));
  normal_.uploadVector(vec4Layer(film.normal, film.light));
}

std::vector<float> DenoiseImage::download(const vk::Buffer& pixels) const {
  const size_t n = size_t(width_) * height_;
  std::vector<float> rgb(n * 3);
  fromVec4Layer(pixels.downloadVector<float>(n * 4), rgb);
  return rgb;
}

DenoiseBindings DenoiseImage::bindings() const {
  DenoiseBindings b;
  b.colour = colour_;
  b.albedo = albedo_;
  b.normal = normal_;
  return b;
}

std::vector<DenoiseTile> denoiseTiles(uint32_t width, uint32_t height, uint32_t maxTile, uint32_t margin) {
  if (maxTile % nn::kImageMultiple || maxTile < 2 * margin + nn::kImageMultiple)
    throw DeviceError("denoiser: tile side " + std::to_string(maxTile) + " leaves no core inside its " +
                      std::to_string(margin) + " px margins");
  std::vector<DenoiseTile> tiles;
  for (const Span& y : spans(height, maxTile, margin))
    for (const Span& x : spans(width, maxTile, margin))
      tiles.push_back({x.start, y.start, x.end - x.start, y.end - y.start, x.core0, y.core0, x.core1, y.core1});
  return tiles;
}

NetworkDenoiser::NetworkDenoiser(const vk::Context& ctx, const nn::ImageUNetWeights& weights,
                                 uint32_t width, uint32_t height, uint32_t maxTile, uint64_t budget)
    : width_(width), height_(height), exposure_(ctx), input_(ctx), output_(ctx) {
  if (!maxTile) maxTile = nn::ImageUNet::maxTileFor(ctx, weights.k, weights.outChannels(), budget);
  const bool kernels = weights.predictsKernels();
  tiles_ = denoiseTiles(width, height, maxTile, kernels ? nn::kImageKpnTileMargin : nn::kImageTileMargin);
  uint32_t largest = 0;
  for (const DenoiseTile& t : tiles_) largest = std::max({largest, t.width, t.height});
  net_ = std::make_unique<nn::ImageUNet>(ctx, weights, largest);
  sums_ = vk::Buffer(ctx, sizeof(g::ExposureSums) * (g::kExposurePartials + 1), vk::MemoryUse::DeviceLocal,
                     "denoise exposure");
  if (kernels) {
    const uint32_t factors = weights.straddleGuided() ? g::kKernelFactorsStraddle
                             : weights.filterGuided() ? g::kKernelFactorsFilter
                             : weights.guided()       ? g::kKernelFactorsGeometry
                                                      : g::kKernelFactorsNone;
    firstKernel_.emplace(ctx, true, false, factors);
    middleKernel_.emplace(ctx, false, false, factors);
    lastKernel_.emplace(ctx, false, true, factors);
    const VkDeviceSize bytes = VkDeviceSize(largest) * largest * 16;
    kernelPing_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "denoise kernel ping");
    kernelPong_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "denoise kernel pong");
  }
}

void NetworkDenoiser::recordKernels(VkCommandBuffer cmd, DenoiseBindings b, g::DenoisePush push) const {
  const vk::BufferRange image = b.out;
  for (uint32_t level = 0; level < g::kKernelLevels; ++level) {
    const bool first = level == 0, last = level + 1 == g::kKernelLevels;
    chainStep(b, level, g::kKernelLevels, image, kernelPing_, kernelPong_);
    push.step = 1u << level;
    (first ? *firstKernel_ : last ? *lastKernel_ : *middleKernel_).record(cmd, b, push);
  }
}

void NetworkDenoiser::record(VkCommandBuffer cmd, const DenoiseImage& image, const vk::Buffer& out,
                             vk::GpuTimer* timer) const {
  DenoiseBindings b = image.bindings();
  b.exposure = sums_;
  b.out = out;
  g::DenoisePush push = imagePush(width_, height_);
  {
    vk::TimedScope scope(timer, cmd, "exposure");
    exposure_.record(cmd, b, push);
  }
  for (const DenoiseTile& t : tiles_) {
    push.tileX = t.x;
    push.tileY = t.y;
    push.tileWidth = t.width;
    push.tileHeight = t.height;
    push.coreX0 = t.coreX0;
    push.coreY0 = t.coreY0;
    push.coreX1 = t.coreX1;
    push.coreY1 = t.coreY1;
    b.tensor = net_->input(t.height, t.width);
    {
      vk::TimedScope scope(timer, cmd, "net input");
      input_.record(cmd, b, push);
    }
    net_->record(cmd, t.height, t.width, timer);
    b.tensor = net_->output(t.height, t.width);
    vk::TimedScope scope(timer, cmd, "net output");
    if (firstKernel_)
      recordKernels(cmd, b, push);
    else
      output_.record(cmd, b, push);
  }
}

AtrousFilter::AtrousFilter(const vk::Context& ctx, uint32_t width, uint32_t height, const AtrousSettings& settings)
    : width_(width), height_(height), settings_(settings), first_(ctx, true, false), middle_(ctx, false, false),
      last_(ctx, false, true), only_(ctx, true, true) {
  const VkDeviceSize bytes = VkDeviceSize(width) * height * 16;
  ping_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "atrous ping");
  pong_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "atrous pong");
}

void AtrousFilter::record(VkCommandBuffer cmd, const DenoiseImage& image, const vk::Buffer& out) const {
  g::DenoisePush push = imagePush(width_, height_);
  push.sigmaLuminance = settings_.sigmaLuminance;
  push.sigmaNormal = settings_.sigmaNormal;
  push.sigmaDepth = settings_.sigmaDepth;
  DenoiseBindings b = image.bindings();
  const uint32_t n = settings_.iterations;
  for (uint32_t i = 0; i < n; ++i) {
    const bool first = i == 0, last = i + 1 == n;
    chainStep(b, i, n, out, ping_, pong_);
    push.step = 1u << i;
    const AtrousPass& pass = first && last ? only_ : first ? first_ : last ? last_ : middle_;
    pass.record(cmd, b, push);
  }
}

std::optional<nn::ImageUNetWeights> defaultImageModel() {
  const auto bytes = defaultImageModelBytes();
  if (bytes.empty()) return std::nullopt;
  return nn::ImageUNetWeights::parse(bytes, kDefaultImageModelName);
}

namespace {

nn::ImageUNetWeights loadModel(const DenoiseSettings& s) {
  if (s.network == DenoiseSettings::Network::File) return nn::ImageUNetWeights::load(s.networkFile);
  auto model = defaultImageModel();
  if (!model) throw InputError("--network default: no image denoiser model shipped in this build");
  return *model;
}

}  // namespace

void DenoiseSettings::check() const {
  if (network != Network::None) loadModel(*this);
}

Denoiser::Denoiser(const vk::Context& ctx, const DenoiseSettings& settings, uint32_t width, uint32_t height)
    : ctx_(ctx), settings_(settings), image_(ctx, width, height), bias_(ctx), converge_(ctx) {
  if (settings.network != DenoiseSettings::Network::None)
    network_ = std::make_unique<NetworkDenoiser>(ctx, loadModel(settings), width, height);
  if (settings.atrous) filter_ = std::make_unique<AtrousFilter>(ctx, width, height);
  lastRanNetwork_ = network_ != nullptr;
  denoised_ = vk::Buffer(ctx, VkDeviceSize(width) * height * 16, vk::MemoryUse::DeviceLocal, "denoised colour");
  unbiased_ = vk::Buffer(ctx, VkDeviceSize(width) * height * 16, vk::MemoryUse::DeviceLocal, "bias-corrected colour");
  out_ = vk::Buffer(ctx, VkDeviceSize(width) * height * 16, vk::MemoryUse::DeviceLocal, "converged colour");
}

const char* Denoiser::name() const {
  return lastRanNetwork_ ? "network" : filter_ ? "atrous" : "none";
}

void Denoiser::apply(FilmLayers& film, std::vector<float>* unconverged) {
  if (!network_ && !filter_) return;
  const auto start = std::chrono::steady_clock::now();
  lastRanNetwork_ = network_ && (!filter_ || film.samples >= kNetworkMinSamples);
  // Below kConvergeMinSamples the film's variance is too rough a guide (shared/denoise.h).
  const bool converge = film.samples >= g::kConvergeMinSamples;
  image_.upload(film);
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    if (lastRanNetwork_)
      network_->record(cmd, image_, denoised_);
    else
      filter_->record(cmd, image_, denoised_);
    if (converge) {
      DenoiseBindings b = image_.bindings();
      g::DenoisePush push = imagePush(image_.width(), image_.height());
      push.samples = film.samples;
      b.denoised = denoised_;
      b.out = unbiased_;
      bias_.record(cmd, b, push);
      b.denoised = unbiased_;
      b.out = out_;
      converge_.record(cmd, b, push);
    }
  });
  if (film.noisy.empty()) film.noisy = film.combined;
  film.combined = image_.download(converge ? out_ : denoised_);
  lastSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (unconverged) *unconverged = image_.download(denoised_);
}

}  // namespace osr::render
