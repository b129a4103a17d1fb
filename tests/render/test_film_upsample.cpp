// render::upsampleBilinear, the viewer's coarse first images (viewer/coarse_start.h): sizes and
// every layer, bilinear weights between pixel centres, and a lamp that does not bleed.
#include <gtest/gtest.h>

#include "render/film.h"

namespace osr::render {
namespace {

FilmLayers constantFilm(int w, int h, float value) {
  FilmLayers f;
  f.allocate(w, h);
  for (auto* layer : {&f.combined, &f.direct, &f.indirect, &f.albedo, &f.normal, &f.depth,
                      &f.variance, &f.light})
    std::fill(layer->begin(), layer->end(), value);
  f.samples = 4;
  return f;
}

TEST(FilmUpsample, SizesEveryLayerAndKeepsAConstant) {
  const FilmLayers from = constantFilm(3, 2, 0.7f);
  FilmLayers into;
  into.width = 12;
  into.height = 8;
  upsampleBilinear(from, into);
  EXPECT_EQ(into.samples, 4u);
  EXPECT_TRUE(into.noisy.empty());
  for (const auto* layer : {&into.combined, &into.direct, &into.indirect, &into.albedo,
                            &into.normal}) {
    ASSERT_EQ(layer->size(), 12u * 8u * 3u);
    for (float v : *layer) EXPECT_NEAR(v, 0.7f, 1e-6f);
  }
  for (const auto* layer : {&into.depth, &into.variance, &into.light}) {
    ASSERT_EQ(layer->size(), 12u * 8u);
    for (float v : *layer) EXPECT_NEAR(v, 0.7f, 1e-6f);
  }
}

TEST(FilmUpsample, BilinearBetweenPixelCentres) {
  // Depth 0 and 4 side by side, doubled: output centres at source x = -0.25 (clamped to 0),
  // 0.25, 0.75 and 1.25 (clamped to 1).
  FilmLayers from = constantFilm(2, 1, 0.f);
  from.depth = {0.f, 4.f};
  FilmLayers into;
  into.width = 4;
  into.height = 2;
  upsampleBilinear(from, into);
  const float expected[4] = {0.f, 1.f, 3.f, 4.f};
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_FLOAT_EQ(into.depth[size_t(y) * 4 + size_t(x)], expected[x]);
}

TEST(FilmUpsample, ALampDoesNotBleedIntoItsNeighbours) {
  // A 100-bright pixel among walls of 0.5, upsampled 4x: linear interpolation puts about 50
  // half-way to the next pixel centre; colour is interpolated as x / (1 + x), which keeps the
  // wall's side of the edge near the wall.
  FilmLayers from = constantFilm(4, 4, 0.5f);
  from.combined[(1 * 4 + 1) * 3 + 0] = from.combined[(1 * 4 + 1) * 3 + 1] =
      from.combined[(1 * 4 + 1) * 3 + 2] = 100.f;
  from.noisy = from.combined;
  FilmLayers into;
  into.width = 16;
  into.height = 16;
  upsampleBilinear(from, into);
  ASSERT_EQ(into.noisy.size(), into.combined.size());
  // Pixel (8, 5) sits at source (1.625, 0.875): 0.375 of the way from the wall pixel (2, 1)
  // to the lamp. Linearly that is 33; as x / (1 + x) 1.22.
  const float v = into.combined[(5 * 16 + 8) * 3];
  EXPECT_GT(v, 0.5f);
  EXPECT_LT(v, 1.5f);
  // The lamp's pixels stay far brighter than the wall (their tone-mapped colour is white),
  // though not at the lamp's radiance: the price of the compression (5.1 at (5, 5)).
  EXPECT_GT(into.combined[(5 * 16 + 5) * 3], 4.f);
  EXPECT_FLOAT_EQ(into.noisy[(5 * 16 + 8) * 3], v);
}

}  // namespace
}  // namespace osr::render
