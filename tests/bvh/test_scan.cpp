// bvh_scan_reduce, _top and _apply against std::exclusive_scan, on sizes that hit segment tails.
#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "bvh/scan.h"
#include "bvh_test_util.h"
#include "common/vk_test.h"

using namespace osr;

TEST(ExclusiveScan, ExclusiveScanMatchesCpu) {
  auto& ctx = test::context();
  bvh::ExclusiveScan scan(ctx);
  std::mt19937 rng(5);
  for (uint32_t count : {1u, 1023u, 1024u, 1025u, 300001u}) {
    std::vector<uint32_t> data(count);
    for (auto& d : data) d = rng() % 100;
    vk::Buffer buf = test::deviceBuffer(ctx, count * 4ull, "scan data");
    vk::Buffer partials = test::deviceBuffer(ctx, bvh::ExclusiveScan::partialsBytes(count), "scan partials");
    buf.uploadVector(data);
    ctx.submitAndWait([&](VkCommandBuffer cmd) { scan.record(cmd, {buf, partials, count}); });
    std::vector<uint32_t> expected(count);
    std::exclusive_scan(data.begin(), data.end(), expected.begin(), 0u);
    EXPECT_EQ(buf.downloadVector<uint32_t>(count), expected) << count;
  }
}
