// nn_conv against the CPU twin convCpu: odd batch sizes, every K the network is run with, each
// layer shape class (first conv from 7 channels, BN epilogue, 8K->4K at 4x4, 1x1 + ReLU),
// reading and writing channel slices (the skip concatenations), fp32 and packed fp16.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdio>

#include "common/vk_test.h"
#include "nn_kernels/conv.h"
#include "shaders/shared/nn.h"
#include "nn_test_util.h"
#include "vk/buffer_view.h"

using namespace osr;

// shaders/shared/nn.h is read by GLSL with std430 push-constant layout: no implicit padding.
static_assert(sizeof(gpu::nn::View) == 16);
static_assert(sizeof(gpu::nn::ConvPush) == 80 && offsetof(gpu::nn::ConvPush, maps) == 32);
static_assert(sizeof(gpu::nn::PoolPush) == 80 && offsetof(gpu::nn::PoolPush, maps) == 32);

namespace {

constexpr uint32_t kDeviceDefault = ~0u;  // ConvCase::tileH: let ConvPass choose

struct ConvCase {
  uint32_t n, cin, cout, width, kernel;
  nn::Activation act;
  bool bn;
  bool half;
  uint32_t srcCTotal, srcC0, dstCTotal, dstC0;
  uint32_t tileH = 0, tileW = 0;
  int share = -1;
  bool texels = true;
  bool inTexels = false;
};

std::string describe(const ConvCase& c) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "n=%u cin=%u cout=%u width=%u kernel=%u act=%u bn=%d half=%d src=%u/%u dst=%u/%u tile=%ux%u share=%d texels=%d in_texels=%d",
                c.n, c.cin, c.cout, c.width, c.kernel, unsigned(c.act), c.bn, c.half, c.srcC0,
                c.srcCTotal, c.dstC0, c.dstCTotal, c.tileH, c.tileW, c.share, c.texels, c.inTexels);
  return buf;
}

void runCase(const ConvCase& c, uint32_t seed) {
  auto& ctx = test::context();
  SCOPED_TRACE(describe(c));
  nn::ConvWeights w;
  w.cin = c.cin;
  w.cout = c.cout;
  w.kernel = c.kernel;
  w.activation = c.act;
  w.batchNorm = c.bn;
  nn::Tensor wt = test::randomTensor(c.cout, c.cin, c.kernel, c.kernel, seed, c.half);
  const float fanScale = 1.0f / std::sqrt(float(c.cin * c.kernel * c.kernel));
  for (float& v : wt.data) v = c.half ? nn::halfToFloat(nn::floatToHalf(v * fanScale * 2)) : v * fanScale * 2;
  w.weight = wt.data;
  w.bias = test::randomTensor(1, 1, 1, c.cout, seed + 1).data;
  w.scale = test::randomTensor(1, 1, 1, c.cout, seed + 2).data;
  w.shift = test::randomTensor(1, 1, 1, c.cout, seed + 3).data;
  if (!c.bn) {
    w.scale.assign(c.cout, 1.0f);
    w.shift.assign(c.cout, 0.0f);
  }
  nn::Tensor full = test::randomTensor(c.n, c.srcCTotal, c.width, c.width, seed + 4, c.half);
  nn::Tensor slice(c.n, c.cin, c.width, c.width);
  for (uint32_t i = 0; i < c.n; ++i)
    for (uint32_t ch = 0; ch < c.cin; ++ch)
      for (uint32_t y = 0; y < c.width; ++y)
        for (uint32_t x = 0; x < c.width; ++x) slice.at(i, ch, y, x) = full.at(i, c.srcC0 + ch, y, x);
  nn::Tensor ref = nn::convCpu(slice, w);

  nn::ConvConfig cfg;
  cfg.kernel = c.kernel;
  cfg.cout = c.cout;
  cfg.width = c.width;
  cfg.activation = c.act;
  cfg.batchNorm = c.bn;
  cfg.inHalf = cfg.outHalf = cfg.weightHalf = c.half;
  // 4x8 unless a case asks otherwise: the device default (8x8 on lavapipe) compiles slowly and
  // is covered by the whole-network tests and DefaultTile below.
  cfg.tileH = c.tileH ? c.tileH : std::min(c.width, 4u);
  cfg.tileW = c.tileW ? c.tileW : std::min(c.width, 8u);
  if (c.tileH == kDeviceDefault) cfg.tileH = cfg.tileW = 0;
  cfg.shareLoads = c.share;
  cfg.weightTexels = c.texels;
  cfg.inputTexels = c.inTexels;
  nn::ConvPass pass(ctx, cfg);
  auto words = pass.packWeights(w);
  auto params = pass.packParams(w);
  vk::Buffer wbuf(ctx, words.size() * 4, vk::MemoryUse::DeviceLocal, "conv weights",
                  VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  wbuf.uploadVector(words);
  vk::BufferView wview(ctx, vk::BufferRange(wbuf), pass.weightTexelFormat(), "conv weight texels");
  vk::Buffer pbuf(ctx, params.size() * 4, vk::MemoryUse::DeviceLocal, "conv params");
  pbuf.uploadVector(params);
  vk::Buffer src = test::deviceTensor(ctx, full.data, c.half, "conv src", VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  vk::BufferView srcView(ctx, vk::BufferRange(src), nn::ConvPass::texelFormat(c.half), "conv src texels");
  const size_t dstCount = size_t(c.n) * c.dstCTotal * c.width * c.width;
  const float sentinel = 1234.0f;  // exact in fp16 too
  vk::Buffer dst = test::deviceTensor(ctx, std::vector<float>(dstCount, sentinel), c.half, "conv dst");

  nn::ConvPass::Args a;
  a.src = {vk::BufferRange(src), c.srcCTotal, c.srcC0, c.half};
  a.dst = {vk::BufferRange(dst), c.dstCTotal, c.dstC0, c.half};
  a.weights = wbuf;
  a.weightTexels = wview.handle();
  a.srcTexels = srcView.handle();
  a.params = pbuf;
  a.maps = c.n;
  a.cin = c.cin;
  a.cout = c.cout;
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, a); });
  std::vector<float> out = test::readTensor(dst, dstCount, c.half);

  std::vector<float> got, want;
  const size_t plane = size_t(c.width) * c.width;
  for (uint32_t i = 0; i < c.n; ++i)
    for (uint32_t ch = 0; ch < c.dstCTotal; ++ch)
      for (size_t p = 0; p < plane; ++p) {
        float v = out[(size_t(i) * c.dstCTotal + ch) * plane + p];
        if (ch >= c.dstC0 && ch < c.dstC0 + c.cout) {
          got.push_back(v);
          want.push_back(ref.data[(size_t(i) * c.cout + ch - c.dstC0) * plane + p]);
        } else {
          ASSERT_EQ(v, sentinel) << "wrote outside its channel slice: map " << i << " channel " << ch;
        }
      }
  // fp32: reordered sums only. fp16: output rounding (2^-11 relative) dominates.
  const double tol = c.half ? 2e-3 : 1e-5;
  EXPECT_LE(test::relError(got, want), tol);
}

}  // namespace

TEST(Conv, FirstLayerFromSevenChannels) {
  for (uint32_t k : {8u, 16u, 64u})
    runCase({3, 7, k, 32, 3, nn::Activation::LeakyRelu, false, false, 7, 0, k, 0}, k);
}

TEST(Conv, BatchNormEpilogueBetweenSlices) {
  for (uint32_t k : {8u, 16u, 64u})
    runCase({3, k, 2 * k, 16, 3, nn::Activation::LeakyRelu, true, false, 2 * k, k, 4 * k, 2 * k}, 10 + k);
}

TEST(Conv, DeepLayersAtLowResolution) {
  for (uint32_t k : {8u, 16u, 64u}) {
    runCase({3, 8 * k, 4 * k, 4, 3, nn::Activation::LeakyRelu, false, false, 8 * k, 0, 8 * k, 0}, 20 + k);
    runCase({1, 2 * k, 4 * k, 8, 3, nn::Activation::LeakyRelu, true, false, 2 * k, 0, 8 * k, 4 * k}, 30 + k);
  }
}

TEST(Conv, DecoderWidthAndOutputLayer) {
  for (uint32_t k : {8u, 16u, 64u}) {
    runCase({3, 2 * k, k, 32, 3, nn::Activation::LeakyRelu, false, false, 2 * k, 0, k, 0}, 40 + k);
    runCase({3, k, 3, 32, 1, nn::Activation::Relu, false, false, k, 0, 3, 0}, 50 + k);
  }
  runCase({5, 7, 5, 32, 3, nn::Activation::None, true, false, 9, 2, 11, 3}, 60);  // odd everything
}

TEST(Conv, TileShapes) {
  for (auto [th, tw] : {std::pair{1u, 4u}, {2u, 16u}, {4u, 8u}})
    runCase({3, 16, 16, 32, 3, nn::Activation::LeakyRelu, true, false, 16, 0, 16, 0, th, tw}, 70 + th);
}

TEST(Conv, DefaultTile) {
  runCase({3, 16, 32, 16, 3, nn::Activation::LeakyRelu, true, false, 16, 0, 32, 0, kDeviceDefault, 0, -1, true, true}, 160);
}

// The GPU path (every lane loads the footprint itself) on lavapipe too.
TEST(Conv, WithoutLoadSharing) {
  runCase({3, 16, 32, 16, 3, nn::Activation::LeakyRelu, true, false, 16, 0, 32, 0, 0, 0, 0}, 100);
  runCase({3, 7, 8, 32, 3, nn::Activation::LeakyRelu, false, true, 7, 0, 8, 0, 0, 0, 0}, 101);
  runCase({3, 8, 3, 32, 1, nn::Activation::Relu, false, false, 8, 0, 3, 0, 0, 0, 0}, 102);
}

// Weights through the storage buffer instead of texels (devices with small texel limits).
TEST(Conv, WeightsFromStorageBuffer) {
  runCase({3, 16, 32, 16, 3, nn::Activation::LeakyRelu, true, false, 16, 0, 32, 0, 0, 0, -1, false}, 110);
  runCase({3, 7, 8, 32, 3, nn::Activation::LeakyRelu, false, true, 7, 0, 8, 0, 0, 0, -1, false}, 111);
}

// Input footprints fetched as RGBA texels and shared over the subgroup (lavapipe's path).
TEST(Conv, InputTexels) {
  using A = nn::Activation;
  for (uint32_t k : {8u, 16u, 64u}) {
    runCase({3, k, 2 * k, 16, 3, A::LeakyRelu, true, false, 2 * k, k, 4 * k, 2 * k, 0, 0, -1, true, true}, 120 + k);
    runCase({3, 8 * k, 4 * k, 4, 3, A::LeakyRelu, false, true, 8 * k, 0, 4 * k, 0, 0, 0, -1, false, true}, 130 + k);
    runCase({3, k, 3, 32, 1, A::Relu, false, false, k, 0, 3, 0, 0, 0, -1, true, true}, 140 + k);
  }
  runCase({5, 7, 5, 32, 3, A::None, true, false, 9, 2, 11, 3, 2, 16, -1, true, true}, 150);
}

TEST(Conv, HalfStorage) {
  for (uint32_t k : {8u, 16u, 64u}) {
    runCase({3, k, 2 * k, 16, 3, nn::Activation::LeakyRelu, true, true, 2 * k, k, 4 * k, 2 * k}, 80 + k);
    runCase({3, 8 * k, 4 * k, 4, 3, nn::Activation::LeakyRelu, false, true, 8 * k, 0, 4 * k, 0}, 90 + k);
  }
}
