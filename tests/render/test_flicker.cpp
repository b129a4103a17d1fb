// render/flicker.h on analytic views: a wall facing the camera at a known depth, seen before
// and after the camera steps sideways, so the pairing's pixel shift is known exactly.
#include "render/flicker.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/wall_camera.h"

namespace osr::render {
namespace {

constexpr uint32_t kSize = 32;

// The wall at depth 4 from x = `x`: one pixel is 8 / 32 = 0.25 world units on it.
gpu::camera::CameraFrame cameraAt(float x) { return test_views::wallCamera(x, kSize); }

std::vector<float> ramp(float scale) {
  std::vector<float> rgb(kSize * kSize * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = scale * (0.1f + float(i % 97) / 97.f);
  return rgb;
}

TEST(Flicker, IdenticalFramesUnderOneCameraAreZero) {
  const std::vector<float> depth(kSize * kSize, 4.f);
  const DepthView v{cameraAt(0.f), &depth};
  const auto pairs = reprojectPairs(v, v);
  // Every pixel but the border ring (no second difference there) pairs with itself.
  ASSERT_EQ(pairs.size(), size_t(kSize - 2) * (kSize - 2));
  for (const PixelPair& p : pairs) ASSERT_EQ(p.current, p.previous);
  const std::vector<float> frame = ramp(1.f);
  EXPECT_EQ(flicker(pairs, frame, frame, frame), 0.0);
  // And a change shows: 10% brighter is (0.1 a)^2 / (a^2 + 0.01) per channel.
  const std::vector<float> brighter = ramp(1.1f);
  double expected = 0.0;
  for (const PixelPair& p : pairs)
    for (int c = 0; c < 3; ++c) {
      const double a = frame[p.current * 3 + c];
      expected += 0.01 * a * a / (a * a + 0.01);
    }
  expected /= 3.0 * pairs.size();
  EXPECT_NEAR(flicker(pairs, brighter, frame, frame), expected, 1e-6 * expected);  // float inputs
}

TEST(Flicker, SidewaysStepPairsPixelsOneStepApart) {
  const std::vector<float> depth(kSize * kSize, 4.f);
  // The camera moves 0.5 right: a wall point moves 2 pixels left in the image.
  const DepthView previous{cameraAt(0.f), &depth}, current{cameraAt(0.5f), &depth};
  const auto pairs = reprojectPairs(current, previous);
  ASSERT_FALSE(pairs.empty());
  for (const PixelPair& p : pairs) {
    EXPECT_EQ(p.previous, p.current + 2) << p.current;
    EXPECT_LT(p.current % kSize, kSize - 2) << "paired outside the previous image";
  }
  // The same wall rendered in both frames (a pattern fixed to the wall) has no flicker.
  std::vector<float> before(kSize * kSize * 3), after(kSize * kSize * 3);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) {
        before[(y * kSize + x) * 3 + c] = float((x * 7 + y * 3 + c) % 11);
        after[(y * kSize + x) * 3 + c] = float(((x + 2) * 7 + y * 3 + c) % 11);
      }
  EXPECT_EQ(flicker(pairs, after, before, after), 0.0);
}

TEST(Flicker, OccludedAndSkyPixelsAreNotPaired) {
  std::vector<float> depth(kSize * kSize, 4.f), previousDepth(kSize * kSize, 4.f);
  for (uint32_t x = 0; x < kSize; ++x) depth[10 * kSize + x] = 0.f;  // a row of sky
  for (uint32_t x = 0; x < kSize; ++x) previousDepth[20 * kSize + x] = 2.f;  // an occluder
  const DepthView current{cameraAt(0.f), &depth}, previous{cameraAt(0.f), &previousDepth};
  for (const PixelPair& p : reprojectPairs(current, previous)) {
    const uint32_t y = p.current / kSize;
    EXPECT_TRUE(y < 9 || y > 11) << "next to the sky row: " << p.current;
    EXPECT_NE(y, 20u) << "occluded in the previous frame: " << p.current;
  }
}

}  // namespace
}  // namespace osr::render
