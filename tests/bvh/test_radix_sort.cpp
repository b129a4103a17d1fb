// The radix sort against std::stable_sort, on sizes that hit chunk tails and with many equal
// keys (stability).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "bvh/radix_sort.h"
#include "bvh/scan.h"
#include "bvh_test_util.h"
#include "common/vk_test.h"
#include "vk/buffer_view.h"

using namespace osr;
namespace bb = gpu::bvh_build;

TEST(RadixSort, RadixSortIsAStableSortOf30BitKeys) {
  auto& ctx = test::context();
  bvh::RadixSort sort(ctx);
  std::mt19937 rng(6);
  for (uint32_t count : {1u, 7u, 511u, 513u, 100003u}) {
    std::vector<uint32_t> keys(count), values(count);
    for (uint32_t i = 0; i < count; ++i) {
      // Few distinct keys in the low half of the sizes: many duplicates test stability.
      keys[i] = (i % 2 ? rng() % 64 : rng()) & ((1u << bb::kRadixKeyBits) - 1);
      values[i] = i;
    }
    uint64_t bytes = count * 4ull;
    auto sortBuffer = [&](const char* name) {
      return vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, name, bvh::RadixSort::kUsage);
    };
    vk::Buffer k = sortBuffer("k"), v = sortBuffer("v"), kt = sortBuffer("kt"), vt = sortBuffer("vt");
    vk::BufferView kView = vk::BufferView::uintWords(ctx, k, "k texels"), vView = vk::BufferView::uintWords(ctx, v, "v texels");
    vk::BufferView ktView = vk::BufferView::uintWords(ctx, kt, "kt texels"), vtView = vk::BufferView::uintWords(ctx, vt, "vt texels");
    uint64_t histBytes = bvh::RadixSort::histogramBytes(count);
    vk::Buffer hist = test::deviceBuffer(ctx, histBytes, "hist");
    vk::Buffer partials = test::deviceBuffer(ctx, bvh::ExclusiveScan::partialsBytes(uint32_t(histBytes / 4)), "partials");
    k.uploadVector(keys);
    v.uploadVector(values);
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
      sort.record(cmd, {k, v, kt, vt, hist, partials, count, kView.handle(), vView.handle(), ktView.handle(), vtView.handle()});
    });
    std::vector<uint32_t> order(count);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
    std::vector<uint32_t> sortedKeys(count);
    for (uint32_t i = 0; i < count; ++i) sortedKeys[i] = keys[order[i]];
    EXPECT_EQ(k.downloadVector<uint32_t>(count), sortedKeys) << count;
    EXPECT_EQ(v.downloadVector<uint32_t>(count), order) << count;
  }
}
