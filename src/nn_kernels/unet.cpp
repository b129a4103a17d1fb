#include "nn_kernels/unet.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <map>
#include <tuple>

#include "common/error.h"
#include "nn_kernels/net_plan.h"
#include "nn_kernels/weights_format.h"

namespace osr::nn {

namespace {

// Intermediate tensors of one chunk: channels as multiples of K, square width. The
// concatenation inputs (kCat*) are written by two producers into their channel halves.
enum ScratchId { kCat32, kT32, kB32, kP16, kCat16, kT16, kU16, kP8, kCat8, kT8, kU8, kP4, kT4, kU4, kScratchCount };
constexpr uint32_t kScratchTimesK[kScratchCount] = {2, 1, 1, 1, 4, 2, 1, 2, 8, 4, 2, 4, 8, 4};
constexpr uint32_t kScratchWidth[kScratchCount] = {32, 32, 32, 16, 16, 16, 16, 8, 8, 8, 8, 4, 4, 4};
constexpr int kExternal = -1;  // the caller's input or output buffer

// The seed's forward() with every concatenation turned into channel-slice writes.
constexpr Step kSteps[] = {
    {Op::Conv, 0, kExternal, 0, kT32, 0, 0},
    {Op::Conv, 1, kT32, 0, kCat32, 1, 0},  // x0 -> second half of decoder2's input
    {Op::Pool, -1, kCat32, 1, kP16, 0, 1},
    {Op::Conv, 2, kP16, 0, kT16, 0, 0},
    {Op::Conv, 3, kT16, 0, kCat16, 2, 0},  // x1
    {Op::Pool, -1, kCat16, 2, kP8, 0, 2},
    {Op::Conv, 4, kP8, 0, kT8, 0, 0},
    {Op::Conv, 5, kT8, 0, kCat8, 4, 0},  // x2
    {Op::Pool, -1, kCat8, 4, kP4, 0, 4},
    {Op::Conv, 6, kP4, 0, kT4, 0, 0},
    {Op::Conv, 7, kT4, 0, kU4, 0, 0},
    {Op::Up, -1, kU4, 0, kCat8, 0, 4},  // x3 -> first half of decoder0's input
    {Op::Conv, 8, kCat8, 0, kT8, 0, 0},
    {Op::Conv, 9, kT8, 0, kU8, 0, 0},
    {Op::Up, -1, kU8, 0, kCat16, 0, 2},  // x4
    {Op::Conv, 10, kCat16, 0, kT16, 0, 0},
    {Op::Conv, 11, kT16, 0, kU16, 0, 0},
    {Op::Up, -1, kU16, 0, kCat32, 0, 1},  // x5
    {Op::Conv, 12, kCat32, 0, kT32, 0, 0},
    {Op::Conv, 13, kT32, 0, kB32, 0, 0},
    {Op::Conv, 14, kB32, 0, kExternal, 0, 0},
};
constexpr uint32_t kConvWidth[kConvCount] = {32, 32, 16, 16, 8, 8, 4, 4, 8, 8, 16, 16, 32, 32, 32};
constexpr uint32_t kPlane = kMapSize * kMapSize;


}  // namespace

UNet::UNet(const vk::Context& ctx, const UNetWeights& w, const UNetOptions& options)
    : ctx_(ctx), k_(w.k), half_(options.half) {
  if (w.convs.size() != size_t(kConvCount)) throw InputError(w.source + ": incomplete weights");
  flopsPerMap_ = w.flopsPerMap();
  const VkDeviceSize elem = half_ ? 2 : 4;

  // fp32 weights are read as texels where every layer fits the device's texel-buffer limit: a
  // texel fetch is a gather on lavapipe, a storage load a loop over the lanes. RGBA16F texels
  // cost more than they save, so fp16 weights stay in the storage buffer
  // (docs/device_notes.md, "The U-Net's kernels").
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(ctx.physicalDevice(), &props);
  bool texels = !half_;
  // Shared input loads read texels on CPU devices when a whole storage range fits a view.
  const bool inTexels = ctx.caps().isCpu() && options.shareLoads != 0 &&
                        ctx.caps().maxStorageBufferRange / 8 <= props.limits.maxTexelBufferElements;
  for (const ConvWeights& c : w.convs) {
    const uint64_t texelCount = uint64_t((c.cin + 3) / 4) * c.kernel * c.kernel * (c.cout + 63);
    texels = texels && texelCount <= props.limits.maxTexelBufferElements;
  }

  // Passes, shared between layers whose specialisation is equal: every ConvConfig field that
  // differs between layers is in the key (cout as its workgroup class; the slope as its bits,
  // so that it is a specialisation constant of its own and a NaN cannot break the ordering).
  std::map<std::tuple<uint32_t, uint32_t, uint32_t, int, uint32_t, bool, bool, bool, bool>, size_t>
      passIndex;
  std::vector<uint32_t> weightWords;
  std::vector<float> params;
  for (int i = 0; i < kConvCount; ++i) {
    const ConvWeights& c = w.convs[i];
    ConvConfig cfg;
    cfg.kernel = c.kernel;
    cfg.cout = c.cout;
    cfg.width = kConvWidth[i];
    cfg.activation = c.activation;
    cfg.slope = c.slope;
    cfg.batchNorm = c.batchNorm;
    cfg.inHalf = half_ && i != 0;  // the caller's maps and predictions are fp32
    cfg.outHalf = half_ && i != kConvCount - 1;
    cfg.weightHalf = half_;
    cfg.tileH = std::min(options.tileH, cfg.width);
    cfg.tileW = std::min(options.tileW, cfg.width);
    cfg.shareLoads = options.shareLoads;
    cfg.weightTexels = texels;
    // Input texels for every layer reading the arena; the caller's maps (layer 0) may lack
    // the texel-buffer usage.
    cfg.inputTexels = inTexels && i != 0;
    auto key = std::make_tuple(cfg.kernel, cfg.width, convWorkgroupClass(ctx, c.cout), int(cfg.activation),
                               std::bit_cast<uint32_t>(cfg.slope), cfg.batchNorm, cfg.inHalf,
                               cfg.outHalf, cfg.inputTexels);
    auto it = passIndex.find(key);
    if (it == passIndex.end()) {
      convPasses_.emplace_back(ctx, cfg);
      it = passIndex.insert_or_assign(key, convPasses_.size() - 1).first;
    }
    const LayerSlot l = packLayer(convPasses_[it->second], it->second, c, weightWords, params);
    layers_.push_back({l.pass, c.cin, c.cout, l.weightOffset, l.weightBytes, l.paramOffset, l.paramBytes});
  }
  weightBuffer_ = vk::Buffer(ctx, weightWords.size() * 4, vk::MemoryUse::DeviceLocal, "unet weights",
                             VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  weightBuffer_.uploadVector(weightWords);
  for (const ConvLayer& l : layers_) {
    const VkDeviceSize texel = half_ ? 8 : 16;  // a dummy single texel when texels are off
    weightViews_.emplace_back(ctx, vk::BufferRange(weightBuffer_, l.weightOffset, texels ? l.weightBytes : texel),
                              convPasses_[l.pass].weightTexelFormat(), "unet weight texels");
  }
  paramBuffer_ = vk::Buffer(ctx, params.size() * 4, vk::MemoryUse::DeviceLocal, "unet params");
  paramBuffer_.uploadVector(params);
  pool_ = std::make_unique<ResamplePass>(ctx, Resample::MaxPool2x2, half_, half_);
  upsample_ = std::make_unique<ResamplePass>(ctx, Resample::Upsample2x, half_, half_);

  // Chunk size: every scratch tensor, the caller's input slice, and the arena under budget.
  VkDeviceSize perMap = 0, largest = kInChannels * kPlane * 4;
  for (int s = 0; s < kScratchCount; ++s) {
    VkDeviceSize b = VkDeviceSize(kScratchTimesK[s]) * k_ * kScratchWidth[s] * kScratchWidth[s] * elem;
    perMap += b;
    largest = std::max(largest, b);
  }
  const uint64_t range = std::min<uint64_t>(ctx.caps().maxStorageBufferRange, 1ull << 32);
  chunk_ = uint32_t(std::min<uint64_t>({options.maxChunk, range / largest,
                                        std::max<uint64_t>(options.scratchBudget / perMap, 1)}));
  chunk_ &= ~1u;  // even, so half-packed tensors of a chunk start on word boundaries
  if (chunk_ == 0) throw DeviceError("unet: one map does not fit the device's buffer range");
  VkDeviceSize offset = 0;
  for (int s = 0; s < kScratchCount; ++s) {
    VkDeviceSize b = VkDeviceSize(kScratchTimesK[s]) * k_ * kScratchWidth[s] * kScratchWidth[s] * elem * chunk_;
    scratch_.push_back({kScratchTimesK[s] * k_, kScratchWidth[s], offset, b});
    offset = alignTensor(offset + b);
  }
  arena_ = vk::Buffer(ctx, offset, vk::MemoryUse::DeviceLocal, "unet activations",
                      VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  for (const Scratch& sc : inTexels ? scratch_ : std::vector<Scratch>{})
    scratchViews_.emplace_back(ctx, vk::BufferRange(arena_, sc.offset, sc.bytes),
                               ConvPass::texelFormat(half_), "unet activation texels");
}

TensorView UNet::view(int s, uint32_t c0) const {
  const Scratch& sc = scratch_[s];
  TensorView v;
  v.range = vk::BufferRange(arena_, sc.offset, sc.bytes);
  v.cTotal = sc.channels;
  v.c0 = c0;
  v.half = half_;
  return v;
}

void UNet::record(VkCommandBuffer cmd, const vk::Buffer& in, VkDeviceSize inOffset,
                  const vk::Buffer& out, VkDeviceSize outOffset, uint32_t maps,
                  vk::GpuTimer* timer) const {
  const VkDeviceSize inMap = kInChannels * kPlane * 4, outMap = kOutChannels * kPlane * 4;
  if (inOffset % kTensorAlign || outOffset % kTensorAlign)
    throw DeviceError("unet: buffer offsets must be multiples of 256 bytes");
  if (inOffset + inMap * maps > in.size() || outOffset + outMap * maps > out.size())
    throw DeviceError("unet: " + std::to_string(maps) + " maps do not fit the given buffers");
  for (uint32_t first = 0; first < maps; first += chunk_) {
    const uint32_t n = std::min(chunk_, maps - first);
    for (const Step& s : kSteps) {
      TensorView src, dst;
      if (s.src == kExternal) {
        src.range = vk::BufferRange(in, inOffset + first * inMap, n * inMap);
        src.cTotal = kInChannels;
      } else {
        src = view(s.src, s.srcC0TimesK * k_);
      }
      if (s.dst == kExternal) {
        dst.range = vk::BufferRange(out, outOffset + first * outMap, n * outMap);
        dst.cTotal = kOutChannels;
      } else {
        dst = view(s.dst, s.dstC0TimesK * k_);
      }
      vk::TimedScope scope(timer, cmd, s.op == Op::Conv ? kConvSpecs[s.conv].name
                                       : s.op == Op::Pool ? "maxpool" : "upsample");
      if (s.op == Op::Conv) {
        const ConvLayer& l = layers_[s.conv];
        ConvPass::Args a;
        a.src = src;
        a.dst = dst;
        a.weights = vk::BufferRange(weightBuffer_, l.weightOffset, l.weightBytes);
        a.weightTexels = weightViews_[s.conv].handle();
        if (s.src != kExternal && !scratchViews_.empty()) a.srcTexels = scratchViews_[s.src].handle();
        a.params = vk::BufferRange(paramBuffer_, l.paramOffset, l.paramBytes);
        a.maps = n;
        a.cin = l.cin;
        a.cout = l.cout;
        convPasses_[l.pass].record(cmd, a);
      } else {
        ResamplePass::Args a;
        a.src = src;
        a.dst = dst;
        a.maps = n;
        a.channels = s.channelsTimesK * k_;
        a.inWidth = scratch_[s.src].width;
        (s.op == Op::Pool ? *pool_ : *upsample_).record(cmd, a);
      }
    }
  }
}

}  // namespace osr::nn
