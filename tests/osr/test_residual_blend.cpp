// The residual blend (shared/osr.h, osr_resolve.comp, docs/osr.md): the variance of the mean
// residual from the passes' second moments, the shrinkage toward the maps where the residual
// is noise and toward the residual where the maps are wrong, and on the device, an image whose
// maps are deliberately coarse: the measured blend beats both the maps alone and the full
// residual, and keeps the first passes noise-free.
#include <gtest/gtest.h>

#include <random>

#include "image/image_metrics.h"
#include "osr/osr_test_util.h"
#include "pt/path_integrator.h"
#include "shaders/shared/osr.h"

using namespace osr;
namespace o = gpu::osr;

namespace {

struct Sums {
  glm::vec4 residual{0.f}, residualSq{0.f};
  float weightSum = 0.f;
};
// n passes of weight 1 whose residual is bias + Gaussian noise of sigma.
Sums passes(int n, float bias, float sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, sigma);
  Sums s;
  for (int k = 0; k < n; ++k) {
    float r = bias + noise(rng);
    s.residual += glm::vec4(r, r, r, 1.f);
    s.residualSq += glm::vec4(r * r, r * r, r * r, 1.f);
    s.weightSum += 1.f;
  }
  return s;
}

}  // namespace

TEST(ResidualBlend, VarianceOfTheMeanFromThePassesSpread) {
  // Averaged over many pixels, the estimate is sigma^2 / n.
  for (int n : {8, 32, 128}) {
    double sum = 0;
    const int pixels = 2000;
    for (int p = 0; p < pixels; ++p) {
      Sums s = passes(n, 0.3f, 2.f, 17u + p);
      sum += o::residualVarianceOfMean(s.residual, s.residualSq, s.weightSum).x;
    }
    EXPECT_NEAR(sum / pixels, 4.0 / n, 0.05 * 4.0 / n) << n << " passes";
  }
  // Unknown (zero) before kResidualMinPasses passes.
  Sums few = passes(int(o::kResidualMinPasses) - 1, 0.f, 1.f, 5u);
  EXPECT_FALSE(o::residualVarianceKnown(few.residualSq, few.weightSum));
  EXPECT_EQ(o::residualVarianceOfMean(few.residual, few.residualSq, few.weightSum).x, 0.f);
  Sums enough = passes(int(o::kResidualMinPasses), 0.f, 1.f, 5u);
  EXPECT_TRUE(o::residualVarianceKnown(enough.residualSq, enough.weightSum));
}

// The composite's pass-to-pass spread (osr_composite's moments): passes of unequal weight
// (coarse grids weigh less), averaged over many pixels, give the variance of the weighted
// mean, sigma^2 sum w^2 / (sum w)^2; one pass gives 0.
TEST(ResidualBlend, CompositeVarianceOfTheWeightedMean) {
  for (int n : {2, 4, 16}) {
    double sum = 0, expected = 0;
    const int pixels = 4000;
    for (int p = 0; p < pixels; ++p) {
      std::mt19937 rng(31u + p);
      std::normal_distribution<float> noise(0.f, 2.f);
      glm::vec4 sq(0.f);
      float w1 = 0.f, w2 = 0.f;
      for (int k = 0; k < n; ++k) {
        const float w = k % 2 ? 1.f : 0.5f, c = 3.f + noise(rng);
        sq += o::weightedMoments(c, w);
        w1 += w, w2 += w * w;
      }
      sum += o::varianceOfWeightedMean(sq);
      expected = 4.0 * w2 / (w1 * w1);
    }
    EXPECT_NEAR(sum / pixels, expected, 0.08 * expected) << n << " passes";
  }
  EXPECT_EQ(o::varianceOfWeightedMean(glm::vec4(9.f, 1.f, 1.f, 3.f)), 0.f);
}

TEST(ResidualBlend, ShrinksTowardTheMapsWhereTheResidualIsNoise) {
  // A neighbourhood of 81 pixels: sumSq estimates 81 (b^2 + V), sumVar 81 V.
  auto blendOf = [](float bias, float sigma, int n, float noiseWeight = 1.f) {
    glm::vec3 sumVar(0.f), sumSq(0.f);
    for (int p = 0; p < 81; ++p) {
      Sums s = passes(n, bias, sigma, 100u + p);
      glm::vec3 mean = glm::vec3(s.residual) / s.weightSum;
      sumVar += o::residualVarianceOfMean(s.residual, s.residualSq, s.weightSum);
      sumSq += mean * mean;
    }
    return o::residualShrinkBlend(sumVar, sumSq, float(n), noiseWeight).x;
  };
  EXPECT_LT(blendOf(0.f, 1.f, 16), 0.15f);   // unbiased maps: keep the noise out
  EXPECT_GT(blendOf(1.f, 1.f, 64), 0.9f);    // b^2 = 1 against V = 1/64: the residual
  // 1 - m V / (b^2 + V) with b^2 = 0.0625, V = 1/64, m = 1 + 5 / 64: about 0.14.
  EXPECT_NEAR(blendOf(0.125f, 1.f, 64), 1.f - (1.f + 5.f / 64) * 0.5f, 0.15f);
  // For an image denoiser the residual's variance counts half (kDenoisedResidualNoiseWeight).
  EXPECT_NEAR(blendOf(0.125f, 1.f, 64, 0.5f), 1.f - 0.5f * (1.f + 5.f / 64) * 0.5f, 0.1f);
  EXPECT_GT(blendOf(0.125f, 1.f, 64, 0.5f), blendOf(0.125f, 1.f, 64) + 0.2f);
  // More passes, more residual, toward 1 (convergence).
  EXPECT_LT(blendOf(0.1f, 1.f, 16), blendOf(0.1f, 1.f, 1024));
  EXPECT_GT(blendOf(0.1f, 1.f, 4096), 0.95f);
  // Unknown before kResidualMinPasses passes: the maps alone.
  EXPECT_EQ(o::residualShrinkBlend(glm::vec3(0.f), glm::vec3(4.f), o::kResidualMinPasses - 1, 1.f).x, 0.f);
}

TEST(ResidualBlend, BeatsMapsAloneAndTheFullResidualOnCoarseMaps) {
  // Cornell at 32 x 32 with one map per 16 x 16 cell: the interpolation is visibly wrong at the
  // walls' corners (biased maps). After 32 passes, the measured blend is closer to the path
  // tracer than the maps alone (ramp n0 huge) and than the whole residual (n0 = 0).
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  const uint32_t size = 32;
  pt::RenderSettings rs;
  rs.width = rs.height = size;
  rs.spp = 2048;
  rs.seed = 3;
  auto p = pt::render(test::context(), *s.gpu, s.bvh, s.camera, rs);
  image::RgbImage ref{int(size), int(size), p.combined};
  auto errorOf = [&](double ramp, uint32_t passes) {
    oneshot::OsrSettings set;
    set.gridStart = set.gridMin = 16;
    set.residualRamp = ramp;
    oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
    auto o = test::renderOsrPasses(osr, s, passes);
    return image::relMse(image::RgbImage{int(size), int(size), o.combined}, ref);
  };
  const double maps = errorOf(1e12, 32), full = errorOf(0.0, 32), blend = errorOf(-1.0, 32);
  std::printf("32 passes relmse: maps alone %.5f, full residual %.5f, blend %.5f\n", maps, full,
              blend);
  EXPECT_LT(blend, maps);
  EXPECT_LT(blend, full);
  // The first passes are the maps' (noise-free): before kResidualMinPasses nothing is blended.
  EXPECT_NEAR(errorOf(-1.0, 3), errorOf(1e12, 3), 1e-9);
}

TEST(ResidualBlend, ADenoisersBlendResolvesTheSamePassesAgain) {
  // OsrIntegrator::setResidualNoiseWeight: the passes so far resolved again with the blend an
  // image denoiser gets, which shows more of the residual (nearer the whole residual's image
  // of the same seed), and back, bit for bit.
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  const uint32_t size = 32;
  oneshot::OsrSettings set;
  set.gridStart = set.gridMin = 16;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
  const std::vector<float> raw = test::renderOsrPasses(osr, s, 16).combined;
  osr.setResidualNoiseWeight(oneshot::kDenoisedResidualNoiseWeight);
  const std::vector<float> forDenoiser = osr.resolve().combined;
  osr.setResidualNoiseWeight(1.f);
  EXPECT_EQ(osr.resolve().combined, raw);
  set.residualRamp = 0.0;
  oneshot::OsrIntegrator whole(test::context(), *s.gpu, s.bvh, size, size, set);
  const std::vector<float> full = test::renderOsrPasses(whole, s, 16).combined;
  double rawGap = 0.0, denoiserGap = 0.0;
  for (size_t i = 0; i < raw.size(); ++i) {
    rawGap += std::abs(raw[i] - full[i]);
    denoiserGap += std::abs(forDenoiser[i] - full[i]);
  }
  std::printf("mean gap to the whole residual: raw blend %.5f, denoiser's %.5f\n",
              rawGap / raw.size(), denoiserGap / raw.size());
  EXPECT_LT(denoiserGap, 0.8 * rawGap);
}
