// render/temporal_reuse.h on analytic views: a wall facing the camera at depth 4, seen by a
// camera that stays or steps sideways by one pixel's width on the wall, so which history pixel
// each pixel takes, and with what weight, is known exactly.
#include "render/temporal_reuse.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "common/vk_test.h"
#include "support/wall_camera.h"

namespace osr::render {
namespace {

constexpr uint32_t kSize = 32;
constexpr uint32_t kSamples = 4;

// The wall at depth 4 from x = `x`: one pixel is 8 / 32 = 0.25 world units on it.
gpu::camera::CameraFrame cameraAt(float x) { return test_views::wallCamera(x, kSize); }

// The wall at `depth` with colour colourOf(column) (grey; direct 0.6 of it, indirect 0.4),
// albedo 0.5 and every pixel's variance `variance`.
template <class ColourOf>
FilmLayers wall(ColourOf colourOf, float variance, float depth = 4.f) {
  FilmLayers f;
  f.allocate(kSize, kSize);
  f.samples = kSamples;
  for (uint32_t i = 0; i < kSize * kSize; ++i) {
    const float c = colourOf(i % kSize);
    for (int k = 0; k < 3; ++k) {
      f.combined[3 * i + k] = c;
      f.direct[3 * i + k] = 0.6f * c;
      f.indirect[3 * i + k] = 0.4f * c;
      f.albedo[3 * i + k] = 0.5f;
    }
    f.normal[3 * i + 2] = 1.f;
    f.depth[i] = depth;
    f.variance[i] = variance;
  }
  return f;
}
FilmLayers flatWall(float colour, float variance, float depth = 4.f) {
  return wall([&](uint32_t) { return colour; }, variance, depth);
}

TEST(TemporalReuse, StillCameraAveragesFramesByTheirSamples) {
  TemporalReuse reuse(test::context(), kSize, kSize, 3.f);
  FilmLayers first = flatWall(1.0f, 0.01f);
  reuse.apply(first, cameraAt(0.f));
  EXPECT_EQ(first.combined[0], 1.0f);  // nothing before it
  EXPECT_EQ(reuse.reusedShare(), 0.0);
  // Equal samples: the mean of the two, with a quarter of each variance.
  FilmLayers second = flatWall(1.2f, 0.01f);
  reuse.apply(second, cameraAt(0.f));
  EXPECT_EQ(reuse.reusedShare(), 1.0);
  for (uint32_t i = 0; i < kSize * kSize; i += 37) {
    EXPECT_NEAR(second.combined[3 * i], 1.1f, 1e-5f) << i;
    EXPECT_NEAR(second.direct[3 * i], 0.66f, 1e-5f) << i;
    EXPECT_NEAR(second.indirect[3 * i], 0.44f, 1e-5f) << i;
    EXPECT_NEAR(second.variance[i], 0.005f, 1e-7f) << i;
    EXPECT_EQ(second.albedo[3 * i], 0.5f);  // the frame's own
  }
  // The history now holds 8 samples (under the cap of 3 x 4): weights 4 and 8.
  FilmLayers third = flatWall(1.0f, 0.01f);
  reuse.apply(third, cameraAt(0.f));
  EXPECT_NEAR(third.combined[3 * 100], (4.f * 1.0f + 8.f * 1.1f) / 12.f, 1e-5f);
  // Under a still camera there is no cap: the fifth takes all 16 samples behind the fourth,
  // as one render of 20 samples would.
  FilmLayers fourth = flatWall(2.0f, 1.0f);
  reuse.apply(fourth, cameraAt(0.f));
  const float third3 = (4.f * 1.0f + 8.f * 1.1f) / 12.f;
  const float fourth4 = (4.f * 2.0f + 12.f * third3) / 16.f;
  EXPECT_NEAR(fourth.combined[3 * 100], fourth4, 1e-5f);
  FilmLayers fifth = flatWall(1.0f, 1.0f);
  reuse.apply(fifth, cameraAt(0.f));
  EXPECT_NEAR(fifth.combined[3 * 100], (4.f * 1.0f + 16.f * fourth4) / 20.f, 1e-5f);
}

TEST(TemporalReuse, MovedCameraCapsTheHistory) {
  TemporalReuse reuse(test::context(), kSize, kSize, 1.f);
  FilmLayers first = flatWall(1.0f, 1.0f);
  reuse.apply(first, cameraAt(0.f));
  FilmLayers second = flatWall(1.0f, 1.0f);
  reuse.apply(second, cameraAt(0.f));  // 8 samples behind it now
  // A step of one pixel: at most 1 x the frame's 4 samples of the 8.
  FilmLayers third = flatWall(2.0f, 1.0f);
  reuse.apply(third, cameraAt(0.25f));
  EXPECT_NEAR(third.combined[3 * (5 * kSize + 5)], 1.5f, 1e-4f);
}

TEST(TemporalReuse, MovedCameraTakesThePixelThatSawTheSamePoint) {
  TemporalReuse reuse(test::context(), kSize, kSize, 1.f);
  // Columns told apart by their colour; the variance is large, so that nothing is rejected.
  FilmLayers before = wall([](uint32_t x) { return 1.f + float(x); }, 1e4f);
  reuse.apply(before, cameraAt(0.f));
  // One pixel to the right: pixel x now sees what pixel x + 1 saw.
  FilmLayers now = flatWall(0.f, 1e4f);
  reuse.apply(now, cameraAt(0.25f));
  for (uint32_t y : {0u, 13u, kSize - 1}) {
    for (uint32_t x = 0; x + 1 < kSize; ++x)
      ASSERT_NEAR(now.combined[3 * (y * kSize + x)], 0.5f * (2.f + float(x)), 1e-3f) << x << "," << y;
    // The last column's point was outside the previous image: the frame's own.
    EXPECT_EQ(now.combined[3 * (y * kSize + kSize - 1)], 0.f);
  }
  EXPECT_NEAR(reuse.reusedShare(), double(kSize - 1) / kSize, 1e-9);
}

// What pixel 100 of `now` holds after `before` under the same camera (`forget`: with the
// history dropped between them), and the share of pixels that took history.
std::pair<float, double> afterHistory(FilmLayers before, FilmLayers now, bool forget = false) {
  TemporalReuse reuse(test::context(), kSize, kSize, 3.f);
  reuse.apply(before, cameraAt(0.f));
  if (forget) reuse.forget();
  reuse.apply(now, cameraAt(0.f));
  return {now.combined[3 * 100], reuse.reusedShare()};
}

TEST(TemporalReuse, HistoryOfAnotherSurfaceOrLightIsNotTaken) {
  using Taken = std::pair<float, double>;
  // Another surface: the history saw a wall at depth 2 where the frame sees one at 4.
  EXPECT_EQ(afterHistory(flatWall(5.f, 1e4f, 2.f), flatWall(1.f, 1e4f)), Taken(1.f, 0.0));
  // Light that changed: 1 against 3 with standard errors of 0.1 is far more than 3 of them.
  EXPECT_EQ(afterHistory(flatWall(1.f, 0.01f), flatWall(3.f, 0.01f)), Taken(3.f, 0.0));
  // A forgotten history (the scene changed), and pixels that see a light, take nothing.
  EXPECT_EQ(afterHistory(flatWall(1.f, 1e4f), flatWall(2.f, 1e4f), true), Taken(2.f, 0.0));
  FilmLayers lamp = flatWall(4.f, 1e4f);
  lamp.light.assign(kSize * kSize, 1.f);
  EXPECT_EQ(afterHistory(flatWall(1.f, 1e4f), lamp), Taken(4.f, 0.0));
  // And the control: the same two frames with history taken.
  EXPECT_EQ(afterHistory(flatWall(1.f, 1e4f), flatWall(2.f, 1e4f)), Taken(1.5f, 1.0));
}

// A pixel astride an edge (its normal the mean of two faces', shorter than 1) takes history
// astride the same edge at the same depth though the mixture turned by 30 degrees; a pixel on
// one face does not.
TEST(TemporalReuse, PixelsAstrideAnEdgeTakeTheSameEdgesHistory) {
  auto withNormal = [](FilmLayers f, glm::vec3 n) {
    for (uint32_t i = 0; i < kSize * kSize; ++i)
      for (int k = 0; k < 3; ++k) f.normal[3 * i + k] = n[k];
    return f;
  };
  const float c30 = std::cos(float(M_PI) / 6.f), s30 = std::sin(float(M_PI) / 6.f);
  const glm::vec3 astride(0.f, 0.f, 0.8f), turned(0.f, 0.8f * s30, 0.8f * c30);
  using Taken = std::pair<float, double>;
  EXPECT_EQ(afterHistory(withNormal(flatWall(1.f, 1e4f), turned), withNormal(flatWall(2.f, 1e4f), astride)),
            Taken(1.5f, 1.0));
  EXPECT_EQ(afterHistory(withNormal(flatWall(1.f, 1e4f), turned / 0.8f), withNormal(flatWall(2.f, 1e4f), astride / 0.8f)),
            Taken(2.f, 0.0));
}

}  // namespace
}  // namespace osr::render
