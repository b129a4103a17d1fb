// The OSR integrator end to end: with raw one-shot maps at every pixel (r = 1, several paths
// per texel) its image is the path tracer's on cornell and room; its error against the path
// tracer falls as passes accumulate (the residual at work); the grid schedule refines,
// weights denser passes more and keeps the maps' share of the work bounded.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <tuple>

#include "image/image_metrics.h"
#include "osr/grid_schedule.h"
#include "osr/osr_test_util.h"
#include "pt/path_integrator.h"

using namespace osr;

namespace {

using test::pathTrace;

// Box-filters a layer into blocks of b x b pixels: a few jittered first hits per pixel and a
// box-filtered reference then agree on geometry, so the comparison measures light.
image::RgbImage blocks(const std::vector<float>& layer, int size, int b) {
  image::RgbImage img{size / b, size / b, std::vector<float>(size_t(size / b) * (size / b) * 3)};
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < 3; ++c)
        img.rgb[((y / b) * (size / b) + x / b) * 3 + c] +=
            layer[(size_t(y) * size + x) * 3 + c] / float(b * b);
  return img;
}

struct Agreement {
  double relmse, lumRatio;
};
// relMSE of 4 x 4 blocks, and their mean luminance ratio with values clamped at 1: a light
// smaller than a pixel (room's lamp) covers a block by a few jittered first hits against the
// reference's 2048, which would otherwise decide the mean alone.
Agreement agree(const std::vector<float>& a, const std::vector<float>& b, int size) {
  auto ia = blocks(a, size, 4), ib = blocks(b, size, 4);
  double relmse = image::relMse(ia, ib);
  for (auto* img : {&ia, &ib})
    for (float& v : img->rgb) v = std::min(v, 1.f);
  return {relmse, image::meanLuminance(ia) / image::meanLuminance(ib)};
}

}  // namespace

class RawDenseMaps : public testing::TestWithParam<const char*> {};

TEST_P(RawDenseMaps, MatchThePathTracer) {
  // Raw maps (no denoiser) at every pixel, 4 paths per texel, 2 jittered passes; the residual's
  // control-variate part left out (ramp n0 huge), so indirect light comes from the maps alone
  // except for lobes too narrow for a map, which are path-traced as in --mode path.
  const std::string scene = GetParam();
  auto s = test::loadForTest(test::referencePath(scene + "/" + scene + ".gltf"));
  const uint32_t size = 24;
  oneshot::OsrSettings set;
  set.denoiser = oneshot::Denoiser::None;
  set.gridStart = set.gridMin = 1;
  set.pathsPerTexel = 2;
  set.directSamples = set.directSamplesLate = 32;
  set.residualSamples = set.residualSamplesLate = 8;
  set.residualRamp = 1e12;
  set.mapShare = 1.0;  // maps every pass
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
  auto o = test::renderOsrPasses(osr, s, 4);
  auto p = pathTrace(s, size, 2048);
  // Tolerances: both sides carry Monte Carlo noise (the maps ~4096 paths of irradiance per
  // pixel, the path tracer 2048 spp) and two jittered first hits per pixel against 2048;
  // 4 x 4 blocks leave noise of relMSE ~1e-3 on cornell, more in the darker room.
  const double tol = scene == "cornell" ? 0.01 : 0.03;
  auto combined = agree(o.combined, p.combined, size);
  for (auto [name, a, b] : {std::tuple{"direct", &o.direct, &p.direct},
                            std::tuple{"indirect", &o.indirect, &p.indirect}}) {
    auto ag = agree(*a, *b, size);
    std::printf("%s %s: relmse %.5f lum ratio %.4f\n", scene.c_str(), name, ag.relmse, ag.lumRatio);
  }
  EXPECT_LT(combined.relmse, tol) << scene << " combined";
  EXPECT_NEAR(combined.lumRatio, 1.0, 0.03) << scene << " combined";
  {  // both count from the first surface past mirrors (room's): the same split
    auto indirect = agree(o.indirect, p.indirect, size);
    EXPECT_LT(indirect.relmse, tol) << "indirect";
    EXPECT_NEAR(indirect.lumRatio, 1.0, 0.03) << "indirect";
    auto direct = agree(o.direct, p.direct, size);
    EXPECT_LT(direct.relmse, tol) << "direct";
  }
  std::printf("%s: combined relmse %.5f lum %.4f\n", scene.c_str(), combined.relmse,
              combined.lumRatio);
}

INSTANTIATE_TEST_SUITE_P(Scenes, RawDenseMaps, testing::Values("cornell", "room"));

TEST(OsrIntegrator, ErrorFallsAsPassesAccumulate) {
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  const uint32_t size = 32;
  auto p = pathTrace(s, size, 4096);
  oneshot::OsrSettings set;  // defaults: blur denoiser, grid 16 -> 8
  set.gridStart = 8;
  set.gridMin = 4;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
  double previous = 1e9;
  test::renderOsrPasses(osr, s, 0);
  auto& ctx = test::context();
  uint32_t done = 0;
  for (uint32_t passes : {4u, 16u, 64u}) {
    for (; done < passes; ++done)
      ctx.submitAndWait([&](VkCommandBuffer cmd) { osr.record(cmd, done, 1, nullptr); });
    auto o = osr.resolve();
    image::RgbImage a{int(size), int(size), o.combined}, b{int(size), int(size), p.combined};
    double e = image::relMse(a, b);
    std::printf("%u passes: relmse %.5f\n", passes, e);
    EXPECT_LT(e, previous) << passes << " passes";
    previous = e;
  }
}

TEST(GridSchedule, RefinesWeightsDenserPassesAndBoundsTheMapShare) {
  oneshot::GridSchedule s(256, 256, 16, 4, 0.5, 3.0, 1);
  EXPECT_TRUE(s.pass(0).traceMaps);
  EXPECT_EQ(s.pass(0).radius, 16u);
  EXPECT_EQ(s.maxMaps(), 64u * 64u);
  uint32_t lastRadius = 16, mapPasses = 0;
  double mapWork = 0, total = 0;
  for (uint32_t k = 0; k < 200; ++k) {
    auto p = s.pass(k);
    EXPECT_LE(p.radius, lastRadius);  // never coarser
    EXPECT_GE(p.radius, 4u);
    EXPECT_FLOAT_EQ(p.weight, float((4.0 / p.radius) * (4.0 / p.radius)));
    lastRadius = p.radius;
    double maps = p.traceMaps ? s.mapsOfRadius(p.radius) * 1024.0 : 0.0;
    mapPasses += p.traceMaps;
    mapWork += maps;
    total += maps + 3.0 * 256 * 256;
  }
  EXPECT_EQ(lastRadius, 4u);
  EXPECT_GT(mapPasses, 5u);
  // The share may pass the bound by at most the last map pass.
  EXPECT_LT(mapWork / total, 0.5 + 64.0 * 64 * 1024 / total);
  // Deterministic.
  oneshot::GridSchedule t(256, 256, 16, 4, 0.5, 3.0, 1);
  EXPECT_EQ(t.pass(150).mapPass, s.pass(150).mapPass);
}

// The variance the denoisers read holds the direct light's noise (osr_direct, osr_resolve) and
// the composite's spread from one map pass to the next (osr_composite). In the emissive
// furnace (every wall emits 1, albedo 0.5) the light is the same at every point, so all the
// spread between two seeds is sampling noise. With maps traced in the first pass only, the
// composite repeats and the variance is the direct light's: it matches the direct layers'
// spread and falls with the light samples. With maps traced every pass (4 maps a pass, so
// their placement matters) the composite's spread is in it too. Before 8 passes the residual
// is not blended in.
namespace {
// The mean over pixels of half the squared luminance difference of two independent
// estimates: one estimate's variance.
double spreadOf(const std::vector<float>& x, const std::vector<float>& y) {
  const size_t n = x.size() / 3;
  double spread = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double d = 0.2126 * (x[3 * i] - y[3 * i]) + 0.7152 * (x[3 * i + 1] - y[3 * i + 1]) +
                     0.0722 * (x[3 * i + 2] - y[3 * i + 2]);
    spread += 0.5 * d * d / double(n);
  }
  return spread;
}
}  // namespace

TEST(OsrIntegrator, VarianceHoldsTheDirectLightAndCompositeNoise) {
  auto s = test::loadForTest(test::writeEmissiveFurnace("osr_variance"));
  const uint32_t size = 32;
  auto render = [&](uint32_t lightSamples, double mapShare, uint32_t seed, double* meanVariance) {
    oneshot::OsrSettings set;
    set.directSamples = lightSamples;
    set.mapShare = mapShare;
    // With maps once, a map every 4 pixels: every pixel has maps around it, so none is path
    // traced in full (whose noise the variance also holds). Every pass: 4 maps a pass, so
    // their placement matters.
    set.gridStart = set.gridMin = mapShare > 0.0 ? 16 : 4;
    oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
    render::FilmLayers f = test::renderOsrPasses(osr, s, 2, seed);
    double sum = 0.0;
    for (float v : f.variance) sum += v;
    *meanVariance = sum / double(f.variance.size());
    return f;
  };
  double v16, v16b, v4, vEvery, vEveryB;
  const render::FilmLayers a = render(16, 0.0, 1, &v16), b = render(16, 0.0, 2, &v16b);
  render(4, 0.0, 1, &v4);
  const double directSpread = spreadOf(a.direct, b.direct);
  const render::FilmLayers c = render(16, 1.0, 1, &vEvery), d = render(16, 1.0, 2, &vEveryB);
  const double compositeSpread = spreadOf(c.combined, d.combined) - spreadOf(c.direct, d.direct);
  std::printf("maps once: mean variance %.3g and %.3g (16 light samples), %.3g (4); direct "
              "spread %.3g. Maps every pass: %.3g and %.3g; the composite's spread %.3g\n",
              v16, v16b, v4, directSpread, vEvery, vEveryB, compositeSpread);
  EXPECT_GT(v16, 0.8 * directSpread);
  EXPECT_LT(v16, 1.25 * directSpread);
  EXPECT_GT(v4 / v16, 3.0);
  EXPECT_LT(v4 / v16, 5.3);
  // A spread of two map passes per pixel is heavy-tailed with 4 maps; its mean is not tight.
  EXPECT_GT(compositeSpread, 0.5 * directSpread);
  EXPECT_GT(std::min(vEvery, vEveryB) - v16, 0.5 * compositeSpread);
}

TEST(OsrIntegrator, VarianceHoldsTheLightsSeenInMirrors) {
  // A near-specular mirror (alpha 0.0081, followed by the G-buffer's sampled chain) showing
  // the edge of a lamp behind the camera: the lamp's light in the pixels along its reflected
  // edge depends on the chain's sampled direction and the pass's jitter, so it is noise, and
  // the film's variance must hold it (it held none: room's mirror kept a firefly through both
  // denoisers). Nothing else lights the mirror's pixels, so their direct layer is that light.
  test::GltfWriter g;
  int mirror = g.material({{"pbrMetallicRoughness",
                            {{"baseColorFactor", {0.9, 0.9, 0.9, 1.0}},
                             {"metallicFactor", 1.0},
                             {"roughnessFactor", 0.09}}}});
  int lamp = g.material(test::GltfWriter::emitter(glm::vec3(5.f), true));
  g.quad({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, mirror);
  g.quad({0, -3, 3}, {3, -3, 3}, {3, 3, 3}, {0, 3, 3}, lamp);  // behind the camera
  g.camera({0.f, 0.f, 2.f}, {0.f, 0.f, 0.f}, 0.6f);
  const std::string path = (test::tempDir("osr_mirror_variance") / "mirror.gltf").string();
  g.write(path);
  auto s = test::loadForTest(path);
  const uint32_t size = 32;
  auto render = [&](uint32_t seed, double* meanVariance) {
    oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, oneshot::OsrSettings{});
    render::FilmLayers f = test::renderOsrPasses(osr, s, 8, seed);
    double sum = 0.0;
    for (float v : f.variance) sum += v;
    *meanVariance = sum / double(f.variance.size());
    return f;
  };
  double va, vb;
  const render::FilmLayers a = render(1, &va), b = render(2, &vb);
  const double spread = spreadOf(a.direct, b.direct);
  std::printf("lamp in a mirror: mean variance %.3g and %.3g, the direct layer's spread %.3g\n",
              va, vb, spread);
  ASSERT_GT(spread, 0.0);
  EXPECT_GT(0.5 * (va + vb), 0.5 * spread);
  EXPECT_LT(0.5 * (va + vb), 2.0 * spread);
}

TEST(OsrIntegrator, FirstHitGuidesLookThroughAMirrorAsPathTracingsDo) {
  // pt/test_path_integrator's floor mirror reflecting a blue wall (or a lamp): OSR's guides
  // are the path tracer's, the wall's tinted albedo, its normal and its virtual image's depth.
  // They were the mirror's own, so the network took the reflection for noise (docs/denoise.md,
  // the 10 s pictures). A lamp in the mirror is not light seen, unlike in path tracing
  // (osr_gbuffer.comp: the chain is sampled, its light is noise).
  for (bool lamp : {false, true}) {
    test::GltfWriter g;
    g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4},
           g.material({{"pbrMetallicRoughness",
                        {{"baseColorFactor", {0.9, 0.9, 0.9, 1.0}}, {"metallicFactor", 1.0}, {"roughnessFactor", 0.0}}}}));
    g.quad({-20, 0, -3}, {20, 0, -3}, {20, 20, -3}, {-20, 20, -3},
           g.material(lamp ? test::GltfWriter::emitter(glm::vec3(2.f), true)
                           : test::GltfWriter::diffuse(glm::vec3(0.2f, 0.5f, 0.8f))));
    g.camera({0.f, 2.f, 2.f}, {0.f, 0.f, 0.f}, 0.5f);
    const std::string path = (test::tempDir("osr_mirror_guides") / "mirror.gltf").string();
    g.write(path);
    auto s = test::loadForTest(path);
    const uint32_t size = 8;
    oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, oneshot::OsrSettings{});
    const render::FilmLayers o = test::renderOsrPasses(osr, s, 16);
    const render::FilmLayers p = pathTrace(s, size, 16);
    for (uint32_t i = 0; i < size * size; ++i) {
      EXPECT_EQ(p.light[i], lamp ? 1.f : 0.f) << i;
      EXPECT_EQ(o.light[i], 0.f) << i;
      if (lamp) continue;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(o.albedo[3 * i + c], p.albedo[3 * i + c], 0.01f * p.albedo[3 * i + c]) << i;
        EXPECT_NEAR(o.normal[3 * i + c], p.normal[3 * i + c], 1e-3f) << i;
      }
      // Both are means over 16 jittered rays of a pixel 0.06 radians wide: 2 %.
      EXPECT_NEAR(o.depth[i], p.depth[i], 0.02f * p.depth[i]) << i;  // the mirror's: 2.3-3.7
    }
  }
}

TEST(OsrIntegrator, EmissiveFurnaceSplitsDirectAndIndirectExactly) {
  // Closed box, every wall emitting 1 with albedo 0.5: radiance 2 everywhere, of which the
  // direct layer (emission seen + one bounce) holds 1.5 and the indirect 0.5.
  auto s = test::loadForTest(test::writeEmissiveFurnace("osr_integrator"));
  oneshot::OsrSettings set;
  set.denoiser = oneshot::Denoiser::None;
  set.gridStart = set.gridMin = 1;
  set.residualRamp = 1e12;
  set.mapShare = 1.0;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, 8, 8, set);
  auto o = test::renderOsrPasses(osr, s, 2);
  auto p = pathTrace(s, 8, 4096);
  double so = 0, sp = 0, dop = 0, dpp = 0;
  for (size_t i = 0; i < o.indirect.size(); ++i) {
    so += o.indirect[i];
    sp += p.indirect[i];
    dop += o.direct[i];
    dpp += p.direct[i];
  }
  const double n = double(o.indirect.size());
  std::printf("furnace indirect osr %.4f pt %.4f direct osr %.4f pt %.4f\n", so / n, sp / n,
              dop / n, dpp / n);
  EXPECT_NEAR(so / n, 0.5, 0.01);   // maps: 2 x 64 x 1024 paths
  EXPECT_NEAR(dop / n, 1.5, 0.04);  // 2 passes x 4 light samples per pixel
  EXPECT_NEAR(sp / n, 0.5, 0.01);
}

TEST(OsrIntegrator, AlphaBlendConvergesToCoverage) {
  // test::writeCoverageScene: the G-buffer's camera rays and the direct pass's shadow rays go
  // through the blended quad with probability 1 - alpha.
  std::string path = (test::tempDir("osr_integrator") / "coverage.gltf").string();
  test::writeCoverageScene(path, "BLEND");
  auto s = test::loadForTest(path);
  const uint32_t size = 16;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, oneshot::OsrSettings{});
  auto o = test::renderOsrPasses(osr, s, 24);
  const double radiance = 0.5 / M_PI * 2.0;
  for (int side = 0; side < 2; ++side) {
    double alpha = side == 0 ? 191 / 255.0 : 64 / 255.0, red = 0, green = 0;
    int n = 0;
    for (uint32_t py = 2; py < size - 2; ++py)
      for (uint32_t px = side == 0 ? 1u : 9u; px < (side == 0 ? 7u : 15u); ++px, ++n) {
        red += o.combined[(py * size + px) * 3];
        green += o.combined[(py * size + px) * 3 + 1];
      }
    std::printf("side %d: green %.4f (expect %.4f) red %.4f (expect %.4f)\n", side, green / n,
                alpha * radiance, red / n, (1 - alpha) * (1 - alpha) * radiance);
    // One G-buffer surface per pixel and pass: 72 x 24 coverage draws per side, whose standard
    // error is 0.0105 of the radiance; 3 of them.
    EXPECT_NEAR(green / n, alpha * radiance, 0.03 * radiance) << "side " << side;
    EXPECT_NEAR(red / n, (1 - alpha) * (1 - alpha) * radiance, 0.03 * radiance) << "side " << side;
  }
}

TEST(MapWeight, FallsWithScreenDistanceNormalsAndDepthGaps) {
  namespace o = osr::gpu::osr;
  const glm::vec3 x(0, 0, 0), n(0, 1, 0);
  const float r = 8.f, scale = 0.1f;  // scale: world size of r pixels
  // The same surface point and normal at the same pixel: full weight.
  EXPECT_FLOAT_EQ(o::mapWeight({4, 4}, {4, 4}, r, x, n, x, n, scale), 1.f);
  // Screen distance: falls monotonically and is 0 from 1.5 r on.
  float last = 2.f;
  for (float d = 0.f; d <= 1.6f * r; d += 1.f) {
    float w = o::mapWeight({4 + d, 4}, {4, 4}, r, x, n, x + glm::vec3(d * 0.01f, 0, 0), n, scale);
    EXPECT_LE(w, last) << d;
    last = w;
  }
  EXPECT_EQ(o::mapWeight({4 + 1.5f * r, 4}, {4, 4}, r, x, n, x, n, scale), 0.f);
  // Points on one plane keep their weight; a map off the pixel's plane by a depth gap of a few
  // grid spacings loses it (the seed's weight grew with depth similarity, backwards).
  float onPlane = o::mapWeight({6, 4}, {4, 4}, r, x, n, {0.05f, 0, 0}, n, scale);
  float gap = o::mapWeight({6, 4}, {4, 4}, r, x, n, {0.05f, 0.3f, 0}, n, scale);
  EXPECT_GT(onPlane, 0.8f);
  EXPECT_LT(gap, 1e-3f * onPlane);
  // Normals: perpendicular surfaces (a wall above a floor) do not share maps; the weight falls
  // as cos^8.
  EXPECT_EQ(o::mapWeight({4, 4}, {4, 4}, r, x, n, x, {1, 0, 0}, scale), 0.f);
  glm::vec3 tilted = glm::normalize(glm::vec3(0.5f, 1.f, 0.f));
  EXPECT_NEAR(o::mapWeight({4, 4}, {4, 4}, r, x, n, x, tilted, scale),
              std::pow(glm::dot(n, tilted), 8.f), 1e-5f);
  // Symmetric in the two points' roles.
  glm::vec3 xg(0.03f, 0.01f, 0.02f), ng = glm::normalize(glm::vec3(0.1f, 1.f, 0.f));
  EXPECT_FLOAT_EQ(o::mapWeight({5, 4}, {4, 4}, r, x, n, xg, ng, scale),
                  o::mapWeight({4, 4}, {5, 4}, r, xg, ng, x, n, scale));
}

TEST(OsrIntegrator, SlicedPassesGiveTheSameImage) {
  // The viewer records a pass in slices (bands of pixels, small chunks of maps, each its own
  // submission); the image equals the whole passes', the U-Net's chunks included.
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  auto& ctx = test::context();
  oneshot::OsrSettings set;
  set.denoiser = oneshot::Denoiser::Unet;
  set.weightsPath = test::dataPath("unet_k8.osrw");
  set.gridStart = 16;
  set.gridMin = 8;
  const uint32_t passes = 3;
  oneshot::OsrIntegrator whole(ctx, *s.gpu, s.bvh, 64, 48, set);
  const render::FilmLayers a = test::renderOsrPasses(whole, s, passes);
  oneshot::OsrIntegrator sliced(ctx, *s.gpu, s.bvh, 64, 48, set);
  sliced.restart(s.camera, 1);
  for (uint32_t k = 0; k < passes; ++k)
    for (uint32_t slice = 0; slice < 7; ++slice)
      ctx.submitAndWait([&](VkCommandBuffer cmd) { sliced.recordSlice(cmd, k, slice, 7, nullptr); });
  const render::FilmLayers b = sliced.resolve();
  EXPECT_EQ(whole.mapsTraced(), sliced.mapsTraced());
  ASSERT_EQ(a.combined.size(), b.combined.size());
  double worst = 0.0;
  for (size_t i = 0; i < a.combined.size(); ++i)
    worst = std::max(worst, double(std::abs(a.combined[i] - b.combined[i])) /
                                (1e-3 + std::abs(a.combined[i])));
  EXPECT_LT(worst, 1e-4);
  EXPECT_EQ(a.depth, b.depth);
}

// The CLI slices long passes by a count that follows measured time (nothing shows the film
// until the end), and the slices cut the maps into other chunks than a whole pass: the image
// must still be the same bits, so that the same seed gives the same image.
TEST(OsrIntegrator, SlicesWithoutPreviewsGiveTheSameBits) {
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  auto& ctx = test::context();
  oneshot::OsrSettings set;
  set.denoiser = oneshot::Denoiser::Unet;  // batches maps by chunk
  set.weightsPath = test::dataPath("unet_k8.osrw");
  set.gridStart = 4;  // 192 maps: 7 slices would cut them into chunks of 28
  set.gridMin = 4;
  set.resolveEverySubmission = false;
  const uint32_t passes = 2;
  oneshot::OsrIntegrator whole(ctx, *s.gpu, s.bvh, 64, 48, set);
  const render::FilmLayers a = test::renderOsrPasses(whole, s, passes);
  for (uint32_t slices : {2u, 7u}) {
    oneshot::OsrIntegrator sliced(ctx, *s.gpu, s.bvh, 64, 48, set);
    sliced.restart(s.camera, 1);
    for (uint32_t k = 0; k < passes; ++k)
      for (uint32_t slice = 0; slice < slices; ++slice)
        ctx.submitAndWait([&](VkCommandBuffer cmd) { sliced.recordSlice(cmd, k, slice, slices, nullptr); });
    const render::FilmLayers b = sliced.resolve();
    EXPECT_EQ(a.combined, b.combined) << slices << " slices";
    EXPECT_EQ(a.depth, b.depth) << slices << " slices";
  }
}

// --time or Ctrl-C stopping the CLI inside a pass (Integrator::abandonUnit): the unfinished
// pass is dropped, the image is the complete passes' to the bit; stopped inside the first
// pass, the image holds what it reached (direct light of the bands done), not nothing.
TEST(OsrIntegrator, AnAbandonedPassIsDropped) {
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  auto& ctx = test::context();
  oneshot::OsrSettings set;
  set.resolveEverySubmission = false;
  oneshot::OsrIntegrator whole(ctx, *s.gpu, s.bvh, 64, 48, set);
  const render::FilmLayers one = test::renderOsrPasses(whole, s, 1);
  oneshot::OsrIntegrator sliced(ctx, *s.gpu, s.bvh, 64, 48, set);
  sliced.restart(s.camera, 1);
  auto slice = [&](uint32_t k, uint32_t i) {
    ctx.submitAndWait([&](VkCommandBuffer cmd) { sliced.recordSlice(cmd, k, i, 8, nullptr); });
  };
  for (uint32_t i = 0; i < 8; ++i) slice(0, i);
  for (uint32_t i = 0; i < 5; ++i) slice(1, i);
  sliced.abandonUnit(1, 5, 8);
  const render::FilmLayers b = sliced.resolve();
  EXPECT_EQ(one.combined, b.combined);
  EXPECT_EQ(one.depth, b.depth);

  sliced.restart(s.camera, 1);
  for (uint32_t i = 0; i < 3; ++i) slice(0, i);
  sliced.abandonUnit(0, 3, 8);
  const render::FilmLayers first = sliced.resolve();
  double lit = 0.0;
  for (float v : first.direct) lit += v;
  EXPECT_GT(lit, 0.0) << "the direct light of the bands done";
}
