#include "nn_kernels/image_unet.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <tuple>

#include "common/error.h"
#include "nn_kernels/net_plan.h"
#include "nn_kernels/weights_format.h"

namespace osr::nn {

namespace {

// The tensors of one tile. The concatenations (kCat*) are written by two producers into their
// channel ranges, cat(upsampled, skip) as image_unet.py's forward() does.
enum TensorId { kIn, kA0, kCat0, kB0, kOut, kP1, kCat1, kD1, kP2, kCat2, kD2, kP3, kM, kTensorCount };
struct TensorSpec {
  uint32_t timesK;  // channels = timesK * K, or `fixed` when 0, or the model's outputs when both are
  uint32_t fixed;
  uint32_t scale;
};
constexpr TensorSpec kTensors[kTensorCount] = {
    {0, kImageInChannels, 0}, {1, 0, 0}, {3, 0, 0}, {1, 0, 0}, {0, 0, 0},
    {1, 0, 1}, {4, 0, 1}, {2, 0, 1}, {2, 0, 2}, {6, 0, 2}, {2, 0, 2}, {2, 0, 3}, {4, 0, 3},
};

// image_unet.py's forward(); conv indices into kImageConvSpecs.
constexpr Step kSteps[] = {
    {Op::Conv, 0, kIn, 0, kA0, 0, 0},     // enc0.0
    {Op::Conv, 1, kA0, 0, kCat0, 2, 0},   // enc0.2 = s0, second part of dec0's input
    {Op::Pool, -1, kCat0, 2, kP1, 0, 1},
    {Op::Conv, 2, kP1, 0, kCat1, 2, 0},   // enc1.1 = s1
    {Op::Pool, -1, kCat1, 2, kP2, 0, 2},
    {Op::Conv, 3, kP2, 0, kCat2, 4, 0},   // enc2.1 = s2
    {Op::Pool, -1, kCat2, 4, kP3, 0, 2},
    {Op::Conv, 4, kP3, 0, kM, 0, 0},      // mid.1
    {Op::Up, -1, kM, 0, kCat2, 0, 4},
    {Op::Conv, 5, kCat2, 0, kD2, 0, 0},   // dec2.0
    {Op::Up, -1, kD2, 0, kCat1, 0, 2},
    {Op::Conv, 6, kCat1, 0, kD1, 0, 0},   // dec1.0
    {Op::Up, -1, kD1, 0, kCat0, 0, 2},
    {Op::Conv, 7, kCat0, 0, kA0, 0, 0},   // dec0.0
    {Op::Conv, 8, kA0, 0, kB0, 0, 0},     // dec0.2
    {Op::Conv, 9, kB0, 0, kOut, 0, 0},    // dec0.4 (1x1, no activation)
};
constexpr uint32_t kStoreMultiple = 8;  // the convolution's pixel tile divides this

uint32_t stored(uint32_t size, uint32_t scale) {
  return ((size >> scale) + kStoreMultiple - 1) / kStoreMultiple * kStoreMultiple;
}
uint32_t channelsOf(const TensorSpec& t, uint32_t k, uint32_t outs) {
  return t.timesK ? t.timesK * k : t.fixed ? t.fixed : outs;
}
VkDeviceSize tensorBytes(const TensorSpec& t, uint32_t k, uint32_t outs, uint32_t tile) {
  const VkDeviceSize side = stored(tile, t.scale);
  return VkDeviceSize(channelsOf(t, k, outs)) * side * side * 4;
}

}  // namespace

uint32_t ImageUNet::maxTileFor(const vk::Context& ctx, uint32_t k, uint32_t outs, uint64_t budget) {
  const uint64_t range = std::min<uint64_t>(ctx.caps().maxStorageBufferRange, 1ull << 32);
  for (uint32_t tile = 2048; tile >= kImageMultiple; tile -= kImageMultiple) {
    uint64_t total = 0, largest = 0;
    for (const TensorSpec& t : kTensors) {
      const VkDeviceSize b = tensorBytes(t, k, outs, tile);
      total += alignTensor(b);
      largest = std::max<uint64_t>(largest, b);
    }
    if (largest <= range && total <= budget) return tile;
  }
  throw DeviceError("image denoiser: not even an 8x8 tile fits the device's buffer range");
}

ImageUNet::ImageUNet(const vk::Context& ctx, const ImageUNetWeights& w, uint32_t maxTile)
    : ctx_(ctx), k_(w.k), outs_(w.outChannels()), maxTile_(maxTile), flopsPerPixel_(w.flopsPerPixel()),
      convs_(w.convs) {
  if (w.convs.size() != size_t(kImageConvCount)) throw InputError(w.source + ": incomplete weights");
  if (maxTile % kImageMultiple || maxTile == 0)
    throw DeviceError("image denoiser: tile side " + std::to_string(maxTile) + " is not a multiple of 8");
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(ctx.physicalDevice(), &props);
  // As the map U-Net (unet.cpp): weights as texels where they fit, and on CPU devices shared
  // input loads through texel views of each tensor.
  bool texels = true;
  for (const ConvWeights& c : w.convs)
    texels = texels && uint64_t((c.cin + 3) / 4) * c.kernel * c.kernel * (c.cout + 63) <=
                           props.limits.maxTexelBufferElements;
  bool inTexels = ctx.caps().isCpu();
  for (const TensorSpec& t : kTensors)
    inTexels = inTexels && tensorBytes(t, k_, outs_, maxTile) / 16 <= props.limits.maxTexelBufferElements;

  std::map<std::tuple<uint32_t, uint32_t, int>, size_t> passIndex;
  std::vector<uint32_t> weightWords;
  std::vector<float> params;
  for (const ConvWeights& c : w.convs) {
    ConvConfig cfg;
    cfg.kernel = c.kernel;
    cfg.cout = c.cout;
    cfg.width = kStoreMultiple;  // picks the pixel tile; sizes come with each dispatch
    cfg.activation = c.activation;
    cfg.batchNorm = false;
    cfg.weightTexels = texels;
    cfg.inputTexels = inTexels;
    auto key = std::make_tuple(cfg.kernel, convWorkgroupClass(ctx, c.cout), int(cfg.activation));
    auto it = passIndex.find(key);
    if (it == passIndex.end()) {
      convPasses_.emplace_back(ctx, cfg);
      it = passIndex.insert_or_assign(key, convPasses_.size() - 1).first;
    }
    layers_.push_back(packLayer(convPasses_[it->second], it->second, c, weightWords, params));
  }
  weightBuffer_ = vk::Buffer(ctx, weightWords.size() * 4, vk::MemoryUse::DeviceLocal,
                             "image unet weights", VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  weightBuffer_.uploadVector(weightWords);
  for (const LayerSlot& l : layers_)
    weightViews_.emplace_back(ctx, vk::BufferRange(weightBuffer_, l.weightOffset, texels ? l.weightBytes : 16),
                              convPasses_[l.pass].weightTexelFormat(), "image unet weight texels");
  paramBuffer_ = vk::Buffer(ctx, params.size() * 4, vk::MemoryUse::DeviceLocal, "image unet params");
  paramBuffer_.uploadVector(params);
  pool_ = std::make_unique<ResamplePass>(ctx, Resample::MaxPool2x2, false, false);
  upsample_ = std::make_unique<ResamplePass>(ctx, Resample::Upsample2x, false, false);

  VkDeviceSize offset = 0;
  for (const TensorSpec& t : kTensors) {
    const VkDeviceSize b = tensorBytes(t, k_, outs_, maxTile);
    tensors_.push_back({channelsOf(t, k_, outs_), t.scale, offset, b});
    offset = alignTensor(offset + b);
  }
  arena_ = vk::Buffer(ctx, offset, vk::MemoryUse::DeviceLocal, "image unet activations",
                      VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  if (inTexels)
    for (const Tensor& t : tensors_)
      tensorViews_.emplace_back(ctx, vk::BufferRange(arena_, t.offset, t.bytes),
                                ConvPass::texelFormat(false), "image unet activation texels");
}

TensorView ImageUNet::view(int tensor, uint32_t c0) const {
  const Tensor& t = tensors_[tensor];
  TensorView v;
  v.range = vk::BufferRange(arena_, t.offset, t.bytes);
  v.cTotal = t.channels;
  v.c0 = c0;
  return v;
}

vk::BufferRange ImageUNet::input(uint32_t th, uint32_t tw) const {
  return vk::BufferRange(arena_, tensors_[kIn].offset, VkDeviceSize(kImageInChannels) * th * tw * 4);
}

vk::BufferRange ImageUNet::output(uint32_t th, uint32_t tw) const {
  return vk::BufferRange(arena_, tensors_[kOut].offset, VkDeviceSize(outs_) * th * tw * 4);
}

void ImageUNet::record(VkCommandBuffer cmd, uint32_t th, uint32_t tw, vk::GpuTimer* timer) const {
  if (th % kImageMultiple || tw % kImageMultiple || !th || !tw || th > maxTile_ || tw > maxTile_)
    throw DeviceError("image denoiser: tile " + std::to_string(tw) + "x" + std::to_string(th) +
                      " is not a multiple of 8 up to " + std::to_string(maxTile_));
  for (const Step& s : kSteps) {
    const uint32_t scale = tensors_[s.src].scale;
    const TensorView src = view(s.src, s.srcC0TimesK * k_), dst = view(s.dst, s.dstC0TimesK * k_);
    if (s.op == Op::Conv) {
      vk::TimedScope scope(timer, cmd, kImageConvSpecs[s.conv].name);
      const LayerSlot& l = layers_[s.conv];
      ConvPass::Args a;
      a.src = src;
      a.dst = dst;
      a.weights = vk::BufferRange(weightBuffer_, l.weightOffset, l.weightBytes);
      a.weightTexels = weightViews_[s.conv].handle();
      if (!tensorViews_.empty()) a.srcTexels = tensorViews_[s.src].handle();
      a.params = vk::BufferRange(paramBuffer_, l.paramOffset, l.paramBytes);
      a.maps = 1;
      a.cin = convs_[s.conv].cin;
      a.cout = convs_[s.conv].cout;
      a.height = stored(th, scale);
      a.width = stored(tw, scale);
      a.validHeight = th >> scale;
      a.validWidth = tw >> scale;
      convPasses_[l.pass].record(cmd, a);
    } else {
      vk::TimedScope scope(timer, cmd, s.op == Op::Pool ? "maxpool" : "upsample");
      const uint32_t outScale = tensors_[s.dst].scale;
      ResamplePass::Args a;
      a.src = src;
      a.dst = dst;
      a.maps = 1;
      a.channels = s.channelsTimesK * k_;
      a.inHeight = stored(th, scale);
      a.inWidth = stored(tw, scale);
      a.outHeight = stored(th, outScale);
      a.outWidth = stored(tw, outScale);
      a.validInHeight = th >> scale;
      a.validInWidth = tw >> scale;
      (s.op == Op::Pool ? *pool_ : *upsample_).record(cmd, a);
    }
  }
}

}  // namespace osr::nn
