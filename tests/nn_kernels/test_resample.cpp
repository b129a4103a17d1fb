// nn_maxpool and nn_upsample against maxPoolCpu / upsampleCpu (PyTorch's align_corners=False
// formula), on odd batch and channel counts, between channel slices, fp32 and packed fp16.
#include <gtest/gtest.h>

#include "common/vk_test.h"
#include "nn_kernels/resample.h"
#include "nn_test_util.h"

using namespace osr;

namespace {

void runCase(nn::Resample kind, uint32_t n, uint32_t channels, uint32_t inWidth, bool half,
             uint32_t srcCTotal, uint32_t srcC0, uint32_t dstCTotal, uint32_t dstC0) {
  auto& ctx = test::context();
  SCOPED_TRACE(testing::Message() << (kind == nn::Resample::MaxPool2x2 ? "pool" : "upsample") << " n=" << n
                                  << " c=" << channels << " w=" << inWidth << " half=" << half << " src="
                                  << srcC0 << "/" << srcCTotal << " dst=" << dstC0 << "/" << dstCTotal);
  nn::Tensor full = test::randomTensor(n, srcCTotal, inWidth, inWidth, n * 7 + channels, half);
  nn::Tensor slice(n, channels, inWidth, inWidth);
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t c = 0; c < channels; ++c)
      for (uint32_t y = 0; y < inWidth; ++y)
        for (uint32_t x = 0; x < inWidth; ++x) slice.at(i, c, y, x) = full.at(i, srcC0 + c, y, x);
  nn::Tensor ref = kind == nn::Resample::MaxPool2x2 ? nn::maxPoolCpu(slice) : nn::upsampleCpu(slice);
  const uint32_t outW = ref.w;
  const size_t dstCount = size_t(n) * dstCTotal * outW * outW;
  const float sentinel = -777.0f;
  vk::Buffer src = test::deviceTensor(ctx, full.data, half, "resample src");
  vk::Buffer dst = test::deviceTensor(ctx, std::vector<float>(dstCount, sentinel), half, "resample dst");
  nn::ResamplePass pass(ctx, kind, half, half);
  nn::ResamplePass::Args a;
  a.src = {vk::BufferRange(src), srcCTotal, srcC0, half};
  a.dst = {vk::BufferRange(dst), dstCTotal, dstC0, half};
  a.maps = n;
  a.channels = channels;
  a.inWidth = inWidth;
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, a); });
  std::vector<float> out = test::readTensor(dst, dstCount, half);
  const size_t plane = size_t(outW) * outW;
  std::vector<float> got, want;
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t c = 0; c < dstCTotal; ++c)
      for (size_t p = 0; p < plane; ++p) {
        float v = out[(size_t(i) * dstCTotal + c) * plane + p];
        if (c >= dstC0 && c < dstC0 + channels) {
          got.push_back(v);
          want.push_back(ref.data[(size_t(i) * channels + c - dstC0) * plane + p]);
        } else {
          ASSERT_EQ(v, sentinel) << "wrote outside its slice: map " << i << " channel " << c;
        }
      }
  EXPECT_LE(test::maxAbsDiff(got, want), half ? 1e-3 : 1e-6);
}

}  // namespace

TEST(Resample, MaxPool) {
  for (uint32_t w : {32u, 16u, 8u}) {
    runCase(nn::Resample::MaxPool2x2, 3, 7, w, false, 7, 0, 7, 0);
    runCase(nn::Resample::MaxPool2x2, 5, 3, w, false, 8, 5, 6, 1);
  }
}

TEST(Resample, UpsampleBilinearAlignCornersFalse) {
  for (uint32_t w : {4u, 8u, 16u}) {
    runCase(nn::Resample::Upsample2x, 3, 7, w, false, 7, 0, 7, 0);
    runCase(nn::Resample::Upsample2x, 5, 3, w, false, 5, 2, 9, 6);
  }
}

TEST(Resample, HalfStorage) {
  runCase(nn::Resample::MaxPool2x2, 3, 5, 16, true, 8, 3, 10, 5);
  runCase(nn::Resample::Upsample2x, 3, 5, 8, true, 8, 3, 10, 5);
}

TEST(Resample, UpsampleMatchesKnownValues) {
  // 2x2 -> 4x4 by hand from PyTorch's formula: row weights (1,0), (.75,.25), (.25,.75), (0,1).
  nn::Tensor t(1, 1, 2, 2);
  t.data = {0, 4, 8, 12};
  nn::Tensor u = nn::upsampleCpu(t);
  const std::vector<float> want = {0, 1, 3, 4, 2, 3, 5, 6, 6, 7, 9, 10, 8, 9, 11, 12};
  EXPECT_EQ(u.data, want);
}
