// The image denoisers: the learned one against PyTorch (tools/weights_pack.py --golden: its
// padding, exposure, network and output transform) on an image whose size is no multiple of
// 8; tiled runs equal untiled ones everywhere (the margin covers the receptive field); the
// a-trous filter keeps a constant image constant, keeps an edge, and removes noise; the
// two convergence passes follow their rules and return to the film only where the denoiser is
// biased.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include "common/vk_test.h"
#include "image/image_io.h"
#include "nn_kernels/weights_format.h"
#include "render/denoiser.h"

using namespace osr;

namespace {

std::vector<float> readFloats(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  EXPECT_TRUE(f.good()) << path;
  std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::vector<float> v(bytes.size() / 4);
  std::memcpy(v.data(), bytes.data(), v.size() * 4);
  return v;
}

// Planar 3 x h x w (PyTorch) to interleaved rgb.
std::vector<float> interleave(const std::vector<float>& planar, size_t pixels) {
  std::vector<float> out(pixels * 3);
  for (size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < 3; ++c) out[3 * i + c] = planar[c * pixels + i];
  return out;
}

render::FilmLayers film(int w, int h) {
  render::FilmLayers f;
  f.width = w;
  f.height = h;
  const size_t n = size_t(w) * h;
  f.combined.assign(n * 3, 0.0f);
  f.albedo.assign(n * 3, 0.5f);
  f.normal.assign(n * 3, 0.0f);
  for (size_t i = 0; i < n; ++i) f.normal[3 * i + 2] = 1.0f;
  f.depth.assign(n, 2.0f);
  f.variance.assign(n, 0.0f);
  return f;
}

// A random HDR image with random guides; with `surfaces`, normals and depth of tilted planes
// in vertical bands (slightly noisy normals, a depth ramp stepping at each band) and a few
// misses, so that the guided kernels' edge-stopping factors are neither all 1 nor all 0, the
// first column of each band straddling the edge (a mean normal of length 0.6-0.7), and a
// variance of a few samples' worth (the luminance squared times 0 to 0.5).
render::FilmLayers randomFilm(int w, int h, uint32_t seed, bool surfaces = false) {
  render::FilmLayers f = film(w, h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (float& v : f.combined) v = std::exp(4.0f * uni(rng) - 2.0f);
  for (float& v : f.albedo) v = uni(rng);
  for (float& v : f.normal) v = 2.0f * uni(rng) - 1.0f;
  if (!surfaces) return f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const int band = x * 5 / w;
      f.normal[3 * i] = 0.3f * float(band - 2) + 0.05f * (uni(rng) - 0.5f);
      f.normal[3 * i + 1] = 0.05f * (uni(rng) - 0.5f);
      f.normal[3 * i + 2] = 1.0f;
      if (x > 0 && (x - 1) * 5 / w != band)
        for (int c = 0; c < 3; ++c) f.normal[3 * i + c] *= 0.6f;
      f.depth[i] = uni(rng) < 0.03f ? 0.0f : 2.0f + 0.5f * float(band) + 0.01f * float(x + y);
      const float lum = 0.2126f * f.combined[3 * i] + 0.7152f * f.combined[3 * i + 1] + 0.0722f * f.combined[3 * i + 2];
      f.variance[i] = 0.5f * uni(rng) * lum * lum;
    }
  return f;
}

std::vector<float> runNetwork(const nn::ImageUNetWeights& w, const render::FilmLayers& f, uint32_t maxTile,
                              size_t* tiles = nullptr) {
  auto& ctx = test::context();
  render::DenoiseImage image(ctx, f.width, f.height);
  image.upload(f);
  render::NetworkDenoiser net(ctx, w, f.width, f.height, maxTile);
  if (tiles) *tiles = net.tiles().size();
  vk::Buffer out(ctx, size_t(f.width) * f.height * 16, vk::MemoryUse::DeviceLocal, "test denoised");
  ctx.submitAndWait([&](VkCommandBuffer cmd) { net.record(cmd, image, out); });
  return image.download(out);
}

std::vector<float> runAtrous(const render::FilmLayers& f) {
  auto& ctx = test::context();
  render::DenoiseImage image(ctx, f.width, f.height);
  image.upload(f);
  render::AtrousFilter filter(ctx, f.width, f.height);
  vk::Buffer out(ctx, size_t(f.width) * f.height * 16, vk::MemoryUse::DeviceLocal, "test filtered");
  ctx.submitAndWait([&](VkCommandBuffer cmd) { filter.record(cmd, image, out); });
  return image.download(out);
}

double maxAbs(const std::vector<float>& v) {
  double m = 0;
  for (float x : v) m = std::max(m, double(std::fabs(x)));
  return m;
}

double maxAbsDiff(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = std::fabs(double(a[i]) - b[i]);
    if (!(d <= m)) m = std::isnan(d) ? INFINITY : d;
  }
  return m;
}

}  // namespace

// tests/data/image_{unet,kpn,kpn2,kpn3,kpn4}_k8_golden: a 37 x 21 image (padded to 40 x 24) through
// PyTorch, by a direct model and kernel-predicting ones without and with the fixed edge-stopping
// factors (random weights, tools/weights_pack.py --golden; the kpn2 one from
// image_unet.randomize(ImageUNet(8, "osr_image_kpn_v2"), 3) saved with its "architecture",
// whose golden image has banded normals, a stepped depth ramp and misses: depth.f32; the kpn3
// one likewise with "osr_image_kpn_v3", whose golden image also has a variance.f32, and the
// kpn4 one with "osr_image_kpn_v4" and randomize seed 4, whose band edges straddle: 47 pixels'
// normals are means of two faces', shorter than kGuideStraddleLength; with the same weights
// as v3, the output differs by up to 40 of 58).
void expectGolden(const std::string& name) {
  const nn::ImageUNetWeights w = nn::ImageUNetWeights::load(test::dataPath(name + ".osrw"));
  const int width = 37, height = 21;
  const size_t n = size_t(width) * height;
  render::FilmLayers f = film(width, height);
  f.combined = interleave(readFloats(test::dataPath(name + "_golden/colour.f32")), n);
  f.albedo = interleave(readFloats(test::dataPath(name + "_golden/albedo.f32")), n);
  f.normal = interleave(readFloats(test::dataPath(name + "_golden/normal.f32")), n);
  if (w.guided()) f.depth = readFloats(test::dataPath(name + "_golden/depth.f32"));
  if (w.filterGuided()) f.variance = readFloats(test::dataPath(name + "_golden/variance.f32"));
  const std::vector<float> want = interleave(readFloats(test::dataPath(name + "_golden/output.f32")), n);
  const std::vector<float> got = runNetwork(w, f, 0);
  const double err = maxAbsDiff(got, want);
  std::printf("golden %s 37x21: max abs err %.3g (max |out| %.3g)\n", name.c_str(), err, maxAbs(want));
  EXPECT_GT(maxAbs(want), 1.0);
  EXPECT_LE(err, 2e-4 * maxAbs(want));
}

TEST(Denoiser, NetworkMatchesPyTorchGolden) { expectGolden("image_unet_k8"); }
TEST(Denoiser, KernelNetworkMatchesPyTorchGolden) { expectGolden("image_kpn_k8"); }
TEST(Denoiser, GuidedKernelNetworkMatchesPyTorchGolden) { expectGolden("image_kpn2_k8"); }
TEST(Denoiser, FilterGuidedKernelNetworkMatchesPyTorchGolden) { expectGolden("image_kpn3_k8"); }
TEST(Denoiser, StraddleGuidedKernelNetworkMatchesPyTorchGolden) { expectGolden("image_kpn4_k8"); }

// Tiles against one tile: the same image, when every margin holds the receptive field.
void expectTiledEqualsUntiled(const std::string& architecture, int width, int height, uint32_t tile,
                              size_t wantTiles) {
  const nn::ImageUNetWeights w = nn::ImageUNetWeights::random(8, 77, architecture);
  const render::FilmLayers f = randomFilm(width, height, 5, w.guided());
  size_t tiles = 0, one = 0;
  const std::vector<float> tiled = runNetwork(w, f, tile, &tiles);
  const std::vector<float> whole = runNetwork(w, f, 0, &one);
  EXPECT_EQ(one, 1u);
  EXPECT_EQ(tiles, wantTiles);
  const double err = maxAbsDiff(tiled, whole);
  std::printf("%s tiled (%zu tiles) vs whole: max abs err %.3g (max |out| %.3g)\n", architecture.c_str(), tiles,
              err, maxAbs(whole));
  EXPECT_GT(maxAbs(whole), 0.0);
  EXPECT_LE(err, 1e-5 * maxAbs(whole));
}

// 96 px tiles: 16 px cores inside 40 px margins, ceil(123 / 16) x ceil(100 / 16).
TEST(Denoiser, TiledEqualsUntiled) { expectTiledEqualsUntiled(nn::kImageArchitecture, 123, 100, 96, 8u * 7u); }

// 200 px tiles: 56 px cores inside 72 px margins (receptive field and kernels),
// ceil(250 / 56) x ceil(220 / 56).
TEST(Denoiser, KernelTiledEqualsUntiled) {
  expectTiledEqualsUntiled(nn::kImageKpnArchitecture, 250, 220, 200, 5u * 4u);
}
TEST(Denoiser, GuidedKernelTiledEqualsUntiled) {
  expectTiledEqualsUntiled(nn::kImageGuidedKpnArchitecture, 250, 220, 200, 5u * 4u);
}
TEST(Denoiser, FilterGuidedKernelTiledEqualsUntiled) {
  expectTiledEqualsUntiled(nn::kImageVarianceKpnArchitecture, 250, 220, 200, 5u * 4u);
}
TEST(Denoiser, StraddleGuidedKernelTiledEqualsUntiled) {
  expectTiledEqualsUntiled(nn::kImageStraddleKpnArchitecture, 250, 220, 200, 5u * 4u);
}

TEST(Denoiser, TilesCoverTheImageOnce) {
  for (auto [w, h, tile] : {std::tuple{3840u, 2160u, 512u}, {37u, 21u, 96u}, {1000u, 9u, 88u}}) {
    std::vector<int> covered(size_t(w) * h, 0);
    for (const render::DenoiseTile& t : render::denoiseTiles(w, h, tile, nn::kImageTileMargin)) {
      EXPECT_EQ(t.x % 8, 0u);
      EXPECT_EQ(t.y % 8, 0u);
      EXPECT_LE(t.width, tile);
      EXPECT_LE(t.height, tile);
      EXPECT_EQ(t.width % 8, 0u);
      // The core lies inside the tile with the margin on each side cut inside the image.
      const uint32_t paddedW = (w + 7) / 8 * 8, paddedH = (h + 7) / 8 * 8;
      EXPECT_TRUE(t.x == 0 || t.coreX0 >= t.x + nn::kImageTileMargin);
      EXPECT_TRUE(t.x + t.width == paddedW || t.coreX1 + nn::kImageTileMargin <= t.x + t.width);
      EXPECT_TRUE(t.y == 0 || t.coreY0 >= t.y + nn::kImageTileMargin);
      EXPECT_TRUE(t.y + t.height == paddedH || t.coreY1 + nn::kImageTileMargin <= t.y + t.height);
      for (uint32_t y = t.coreY0; y < t.coreY1; ++y)
        for (uint32_t x = t.coreX0; x < t.coreX1; ++x) ++covered[size_t(y) * w + x];
    }
    EXPECT_EQ(std::count(covered.begin(), covered.end(), 1), ptrdiff_t(covered.size())) << w << "x" << h;
  }
}

TEST(Denoiser, AtrousKeepsAConstantImage) {
  render::FilmLayers f = film(64, 48);
  for (size_t i = 0; i < f.combined.size(); ++i) f.combined[i] = 0.3f + 0.1f * float(i % 3);
  f.variance.assign(f.variance.size(), 0.01f);
  const std::vector<float> got = runAtrous(f);
  EXPECT_LE(maxAbsDiff(got, f.combined), 1e-5);
}

// Two halves facing different ways, with noise: the filter smooths each half and keeps the
// edge between them (no light crosses it).
TEST(Denoiser, AtrousKeepsAnEdgeAndRemovesNoise) {
  const int w = 64, h = 48;
  render::FilmLayers f = film(w, h);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const bool left = x < w / 2;
      const float level = left ? 1.0f : 0.2f;
      for (int c = 0; c < 3; ++c) f.combined[3 * i + c] = level * 0.5f * (1.0f + noise(rng));
      f.normal[3 * i] = left ? 0.0f : 1.0f;
      f.normal[3 * i + 2] = left ? 1.0f : 0.0f;
      f.variance[i] = std::pow(level * 0.5f * 0.1f, 2.0f);
    }
  const std::vector<float> got = runAtrous(f);
  double errIn = 0, errOut = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float want = (x < w / 2 ? 1.0f : 0.2f) * 0.5f;
      for (int c = 0; c < 3; ++c) {
        errIn += std::pow(f.combined[3 * i + c] - want, 2.0);
        errOut += std::pow(got[3 * i + c] - want, 2.0);
      }
      // Next to the edge too: within 10% of its own side's level.
      if (x == w / 2 - 1 || x == w / 2) {
        EXPECT_NEAR(got[3 * i], want, 0.1 * want) << x << "," << y;
      }
    }
  std::printf("a-trous on a noisy edge: squared error %.4g -> %.4g\n", errIn, errOut);
  EXPECT_LT(errOut, 0.1 * errIn);
}

// The column where two faces meet is covered a quarter by one, three quarters by the other:
// its film normal is the average of theirs (length 0.79) and its colour their mean.
// Unnormalized, its normal agreed less with itself (0.625) than with the larger face (0.75),
// so the filter replaced it by that face's level (or by 0 where every weight fell below
// float's range): the bright and black edge pixels of cornell's boxes.
TEST(Denoiser, AtrousKeepsAPixelThatStraddlesAnEdge) {
  const int w = 64, h = 48;
  render::FilmLayers f = film(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float side = x < w / 2 ? 1.0f : x > w / 2 ? 0.0f : 0.25f;  // share of the left face
      for (int c = 0; c < 3; ++c) f.combined[3 * i + c] = 0.5f * (0.2f + 0.8f * side);
      f.normal[3 * i] = 1.0f - side;
      f.normal[3 * i + 2] = side;
      f.variance[i] = 1e-4f;
    }
  const std::vector<float> got = runAtrous(f);
  for (int y = 0; y < h; ++y) {
    const size_t i = size_t(y) * w + w / 2;
    EXPECT_NEAR(got[3 * i], f.combined[3 * i], 0.02 * f.combined[3 * i]) << "row " << y;
  }
}

// Two faces of levels 0.4 and 0.5 (two walls at a corner) meeting along a slanted edge (1
// pixel across per 6 down), with noise: the pixels the edge crosses are covered by the two in
// shares that change along it, and their film normals are the means of the faces' (shorter
// than 1). Compared by their unit normals, such a pixel agreed with almost no other and kept
// its noise (0.98x its error); compared by the means (normalLogFactor), it averages with the
// pixels along the edge of about its own mix (0.32x). What that costs is bias where the faces
// differ a lot: with levels 0.1 and 0.5, the kernels of tools/image_unet.py with zero logits
// give 0.95x on this edge (1.0x by unit normals), and at a slope of 1 in 3, 2.0x (1.2x).
TEST(Denoiser, AtrousSmoothsPixelsAlongAnEdge) {
  const int w = 64, h = 48, sub = 16;
  render::FilmLayers f = film(w, h);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.2f);
  std::vector<float> level(size_t(w) * h), share(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      int left = 0;  // subpixels left of the edge x = 28 + y / 6
      for (int sy = 0; sy < sub; ++sy)
        for (int sx = 0; sx < sub; ++sx)
          left += x + (sx + 0.5f) / sub < 28.0f + (y + (sy + 0.5f) / sub) / 6.0f;
      share[i] = float(left) / float(sub * sub);
      level[i] = 0.5f * (0.8f + 0.2f * share[i]);
      const float n = 1.0f + noise(rng);
      for (int c = 0; c < 3; ++c) f.combined[3 * i + c] = level[i] * n;
      f.normal[3 * i] = 1.0f - share[i];
      f.normal[3 * i + 2] = share[i];
      f.variance[i] = std::pow(level[i] * 0.2f, 2.0f);
    }
  const std::vector<float> got = runAtrous(f);
  double errIn = 0, errOut = 0, bias = 0;
  int count = 0;
  for (size_t i = 0; i < level.size(); ++i) {
    if (share[i] < 0.1f || share[i] > 0.9f) continue;
    errIn += std::pow(f.combined[3 * i] - level[i], 2.0) / (level[i] * level[i]);
    errOut += std::pow(got[3 * i] - level[i], 2.0) / (level[i] * level[i]);
    bias += (got[3 * i] - level[i]) / level[i];
    ++count;
  }
  bias /= count;
  std::printf("a-trous on %d pixels an edge crosses: relative squared error %.4g -> %.4g, bias %.3f\n", count,
              errIn / count, errOut / count, bias);
  EXPECT_GT(count, 30);
  EXPECT_LT(errOut, 0.6 * errIn);
  EXPECT_LT(std::fabs(bias), 0.02);
}

// A lamp in a noisy ceiling, with the ceiling's normal, depth and albedo (a flat emissive
// quad): flagged as light seen directly, its pixels keep their colour and the ceiling beside
// them keeps its level; unflagged, the same image gets a halo (so the flag is what keeps it
// out). Both denoisers, the network with random weights (whose kernels spread everywhere).
render::FilmLayers ceilingWithLamp(bool flagged) {
  const int w = 64, h = 48;
  render::FilmLayers f = film(w, h);
  f.light.assign(size_t(w) * h, 0.0f);
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.0f, 0.2f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const bool lamp = std::abs(x - w / 2) < 6 && std::abs(y - h / 2) < 4;
      for (int c = 0; c < 3; ++c) f.combined[3 * i + c] = lamp ? 100.0f : 0.25f * (1.0f + noise(rng));
      f.variance[i] = lamp ? 0.0f : std::pow(0.25f * 0.2f, 2.0f);
      if (lamp && flagged) f.light[i] = 1.0f;
    }
  return f;
}

// The mean of the ceiling pixels within 4 pixels of the lamp, over the ceiling's level; the
// largest relative change of a lamp pixel.
std::pair<double, double> lampHalo(const render::FilmLayers& f, const std::vector<float>& got) {
  double ring = 0, lampChange = 0;
  int count = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const size_t i = size_t(y) * f.width + x;
      const int dx = std::abs(x - f.width / 2), dy = std::abs(y - f.height / 2);
      if (dx < 6 && dy < 4) {
        lampChange = std::max(lampChange, std::fabs(double(got[3 * i]) - f.combined[3 * i]) / f.combined[3 * i]);
      } else if (dx < 10 && dy < 8) {
        ring += got[3 * i];
        ++count;
      }
    }
  return {ring / count / 0.25, lampChange};
}

TEST(Denoiser, LightsSeenDirectlyStayOutOfTheirNeighbours) {
  const nn::ImageUNetWeights net = nn::ImageUNetWeights::random(8, 31, nn::kImageKpnArchitecture);
  const render::FilmLayers flagged = ceilingWithLamp(true), unflagged = ceilingWithLamp(false);
  const auto [atrousRing, atrousLamp] = lampHalo(flagged, runAtrous(flagged));
  const auto [netRing, netLamp] = lampHalo(flagged, runNetwork(net, flagged, 0));
  const auto [haloRing, haloLamp] = lampHalo(unflagged, runNetwork(net, unflagged, 0));
  std::printf("ceiling beside a lamp / its level: a-trous %.3f, network %.3f (unflagged %.3f); "
              "lamp change %.2g, %.2g\n", atrousRing, netRing, haloRing, atrousLamp, netLamp);
  EXPECT_NEAR(atrousRing, 1.0, 0.1);
  EXPECT_NEAR(netRing, 1.0, 0.1);
  EXPECT_GT(haloRing, 1.1);
  EXPECT_LE(atrousLamp, 1e-5);
  EXPECT_LE(netLamp, 1e-3);
}

namespace {

// A convergence pass (render::BiasPass or render::ConvergePass) on `f` (its colour and
// variance) and a denoised colour, on the device.
template <class Pass>
std::vector<float> runConvergePass(const render::FilmLayers& f, const std::vector<float>& denoised) {
  auto& ctx = test::context();
  render::DenoiseImage image(ctx, f.width, f.height);
  image.upload(f);
  const VkDeviceSize bytes = VkDeviceSize(f.width) * f.height * 16;
  vk::Buffer in(ctx, bytes, vk::MemoryUse::DeviceLocal, "test denoised");
  in.uploadVector(render::vec4Layer(denoised, {}));
  vk::Buffer out(ctx, bytes, vk::MemoryUse::DeviceLocal, "test converged");
  Pass pass(ctx);
  render::DenoiseBindings b = image.bindings();
  b.denoised = in;
  b.out = out;
  gpu::denoise::DenoisePush push{};
  push.width = uint32_t(f.width);
  push.height = uint32_t(f.height);
  push.samples = f.samples;
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, b, push); });
  return image.download(out);
}

std::vector<float> runConverge(const render::FilmLayers& f, const std::vector<float>& denoised) {
  return runConvergePass<render::ConvergePass>(f, denoised);
}

// lib/converge_window.glsl on the CPU: how much pixel q counts in pixel p's window sums, and
// the factor k on the noise from the window's sums.
double convergeWeight(const render::FilmLayers& f, size_t p, size_t q) {
  double dn2 = 0;
  for (int c = 0; c < 3; ++c) dn2 += std::pow(double(f.normal[3 * q + c]) - f.normal[3 * p + c], 2);
  return std::max(std::exp(-gpu::denoise::kConvergeNormalSigma * dn2), double(gpu::denoise::kConvergeWeightFloor));
}

double convergeNoiseFactor(double scale, double noise, double level, double count) {
  return 1.0 + scale * std::sqrt(noise / count) / std::max(level / count, 1e-4);
}

// Both convergence passes, as the Denoiser runs them.
std::vector<float> runBiasAndConverge(const render::FilmLayers& f, const std::vector<float>& denoised) {
  return runConverge(f, runConvergePass<render::BiasPass>(f, denoised));
}

}  // namespace

// The rule of shared/denoise.h on the CPU: lambda from the 3 x 3 sums of the squared luminance
// gap and the variance (one sample's worth of the denoised level where it is 0), each
// neighbour weighted by how alike its normal is, and k from the window's relative standard
// error, clipped at the image's edges.
TEST(Denoiser, ConvergeFollowsTheShrinkageRule) {
  render::FilmLayers f = randomFilm(37, 21, 5, true);
  for (float& v : f.variance) v *= 1e-3f;
  for (size_t i = 0; i < f.variance.size(); i += 7) f.variance[i] = 0.0f;  // unknown: one sample's worth
  f.samples = 100;
  render::FilmLayers d = randomFilm(37, 21, 6);
  // The left half close to the film (a gap the noise explains), the right half far from it.
  for (size_t i = 0; i < d.combined.size(); ++i)
    if ((i / 3) % size_t(f.width) < size_t(f.width / 2)) d.combined[i] = f.combined[i] * (1.0f + 0.01f * (d.combined[i] - 1.0f));
  const std::vector<float> got = runConverge(f, d.combined);
  const image::RgbImage film{f.width, f.height, f.combined}, denoised{f.width, f.height, d.combined};
  std::vector<float> want(got.size());
  size_t kept = 0, returned = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const size_t p = size_t(y) * f.width + x;
      double gap = 0, noise = 0, level = 0, count = 0;
      for (int qy = std::max(y - 1, 0); qy <= std::min(y + 1, f.height - 1); ++qy)
        for (int qx = std::max(x - 1, 0); qx <= std::min(x + 1, f.width - 1); ++qx) {
          const size_t q = size_t(qy) * f.width + qx;
          const double w = convergeWeight(f, p, q);
          const double l = std::max(denoised.luminance(q), 0.0), g = film.luminance(q) - l;
          gap += w * g * g;
          noise += w * (f.variance[q] > 0 ? f.variance[q] : l * l / f.samples);
          level += w * l;
          count += w;
        }
      const double k = convergeNoiseFactor(gpu::denoise::kConvergeNoiseScale, noise, level, count);
      const double lambda = gap > 0 ? std::clamp(1.0 - k * noise / gap, 0.0, 1.0) : 0.0;
      kept += lambda == 0.0;
      returned += lambda > 0.99;
      for (int c = 0; c < 3; ++c)
        want[3 * p + c] = float(d.combined[3 * p + c] + lambda * (f.combined[3 * p + c] - d.combined[3 * p + c]));
    }
  std::printf("converge 37x21: %zu pixels kept denoised, %zu returned to the film; max abs err %.3g\n", kept,
              returned, maxAbsDiff(got, want));
  EXPECT_GT(kept, 0u);
  EXPECT_GT(returned, 0u);
  EXPECT_LT(kept + returned, size_t(f.width) * f.height);  // some pixels in between
  EXPECT_LE(maxAbsDiff(got, want), 1e-4 * maxAbs(want));
}

// A flat grey film with noise of the variance it reports, denoised to its true level except in
// one band, where the denoiser is off by far more than the noise: the band returns to the film,
// beside a lamp in it too, and the rest keeps the denoised level.
TEST(Denoiser, ConvergeReturnsToTheFilmOnlyWhereTheDenoiserIsBiased) {
  const int w = 64, h = 48;
  render::FilmLayers f = film(w, h);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::vector<float> denoised(f.combined.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float level = x >= 24 && x < 40 ? 0.8f : 0.5f;
      const float n = noise(rng);
      for (int c = 0; c < 3; ++c) {
        f.combined[3 * i + c] = level + n;
        denoised[3 * i + c] = 0.5f;  // the band's 0.8 blurred away
      }
      f.variance[i] = 0.01f * 0.01f;
    }
  // A lamp in the band, kept by the denoiser: its variance must not hold its neighbours back.
  const size_t lamp = size_t(h / 2) * w + 32;
  for (int c = 0; c < 3; ++c) f.combined[3 * lamp + c] = denoised[3 * lamp + c] = 1000.0f;
  f.variance[lamp] = 1e4f;
  f.light.assign(size_t(w) * h, 0.0f);
  f.light[lamp] = 1.0f;
  const std::vector<float> got = runConverge(f, denoised);
  double besideLamp = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx || dy) besideLamp = std::max(besideLamp, std::fabs(got[3 * (lamp + dy * w + dx)] - 0.8));
  EXPECT_LE(besideLamp, 0.05) << "the lamp's variance held its neighbours at the denoised level";
  EXPECT_EQ(got[3 * lamp], 1000.0f);
  double bandErr = 0, restErr = 0, restRawErr = 0;
  int band = 0, rest = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 1; x < w - 1; ++x) {
      const size_t i = size_t(y) * w + x;
      if (i == lamp) continue;
      if (x >= 25 && x < 39) {
        bandErr += std::fabs(got[3 * i] - 0.8f);
        ++band;
      } else if (x < 23 || x > 40) {
        restErr += std::fabs(got[3 * i] - 0.5f);
        restRawErr += std::fabs(f.combined[3 * i] - 0.5f);
        ++rest;
      }
    }
  std::printf("band: mean |error| %.4f (blurred 0.3); rest %.5f (film %.5f)\n", bandErr / band, restErr / rest,
              restRawErr / rest);
  EXPECT_LE(bandErr / band, 0.01);               // the film's noise, not the denoiser's 0.3
  EXPECT_LE(restErr / rest, 0.15 * restRawErr / rest);  // the denoised level kept
}

// Two faces meet at an edge whose pixels straddle both (a mean normal between theirs). The
// denoiser got the faces right and the edge 3 standard deviations of the film's noise off: the
// edge returns to the film, and the faces beside it keep the denoised level (0.3x the film's
// error). Were every pixel of the 3 x 3 window counted alike, the faces' unbiased gaps would
// dilute the edge's, leaving it more of its bias, and the edge's gaps would pull the faces
// beside it most of the way back to the film's noise (0.7x its error).
TEST(Denoiser, ConvergeReturnsAnEdgeWithoutTheFacesBesideIt) {
  const int w = 64, h = 48, edge = 32;
  const float sigma = 0.01f, bias = 3.0f * sigma;
  render::FilmLayers f = film(w, h);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, sigma);
  std::vector<float> denoised(f.combined.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float level = x < edge ? 0.5f : x == edge ? 0.6f : 0.7f;
      const float n = noise(rng);
      for (int c = 0; c < 3; ++c) {
        f.combined[3 * i + c] = level + n;
        denoised[3 * i + c] = x == edge ? level + bias : level;
      }
      f.normal[3 * i] = x < edge ? 0.0f : x == edge ? 0.5f : 1.0f;
      f.normal[3 * i + 2] = x < edge ? 1.0f : x == edge ? 0.5f : 0.0f;
      f.variance[i] = sigma * sigma;
    }
  f.samples = 100;
  const std::vector<float> got = runConverge(f, denoised);
  double edgeErr = 0, edgeBias = 0, besideErr = 0, besideRawErr = 0;
  for (int y = 1; y < h - 1; ++y) {
    const size_t e = size_t(y) * w + edge;
    edgeErr += std::fabs(got[3 * e] - 0.6f);
    edgeBias += got[3 * e] - 0.6f;
    for (const size_t i : {e - 1, e + 1}) {
      const float level = i < e ? 0.5f : 0.7f;
      besideErr += std::fabs(got[3 * i] - level);
      besideRawErr += std::fabs(f.combined[3 * i] - level);
    }
  }
  edgeErr /= h - 2;
  edgeBias /= h - 2;
  std::printf("edge: mean |error| %.4f, mean error %.4f (denoised %.3f); faces beside it %.5f (film %.5f)\n",
              edgeErr, edgeBias, bias, besideErr / (2 * (h - 2)), besideRawErr / (2 * (h - 2)));
  EXPECT_LE(edgeErr, 0.5 * bias);
  EXPECT_LE(edgeBias, 0.2 * bias);  // the bias left on the edge
  EXPECT_LE(besideErr, 0.4 * besideRawErr);
}

// Where no neighbour shares a pixel's geometry (every normal different: fine detail, foliage),
// the window must not shrink to the pixel alone: one sample of its own noise would return it to
// the film whenever its gap happens to exceed its variance. Denoised exactly, the film's
// heavy-tailed noise (a few bright paths, as under small lamps) stays out.
TEST(Denoiser, ConvergeKeepsNeighboursWhereNoneSharesTheGeometry) {
  const int w = 64, h = 48;
  render::FilmLayers f = film(w, h);
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<float> denoised(f.combined.size(), 0.5f);
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    // 16 paths, most of them a little dark and now and then one far too bright (mean 0.5: 0.1 x
    // 3.2 + 0.9 x 0.2): a pixel that met no bright path is dark and reports a small variance.
    double sum = 0, sumSq = 0;
    for (int k = 0; k < 16; ++k) {
      const double path = uni(rng) < 0.1f ? 3.2 : 0.15 + 0.1 * uni(rng);
      sum += path;
      sumSq += path * path;
    }
    const double mean = sum / 16;
    for (int c = 0; c < 3; ++c) f.combined[3 * i + c] = float(mean);
    f.variance[i] = float((sumSq / 16 - mean * mean) / 15);
    for (int c = 0; c < 3; ++c) f.normal[3 * i + c] = 2.0f * uni(rng) - 1.0f;
  }
  f.samples = 16;
  const std::vector<float> got = runConverge(f, denoised);
  double err = 0, rawErr = 0;
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    err += std::pow(got[3 * i] - 0.5, 2);
    rawErr += std::pow(f.combined[3 * i] - 0.5, 2);
  }
  std::printf("normals all different: squared error %.4f of the film's\n", err / rawErr);
  EXPECT_LE(err, 0.05 * rawErr);  // 0.33 with no floor
}

// The first pass's rule (shared/denoise.h) on the CPU: the 5 x 5 weighted mean of the film's gap
// from the denoised colour, added where its luminance is more than sqrt(k) standard errors of
// the mean, shrunk by the positive-part James-Stein factor; a pixel that saw light directly
// keeps its denoised colour and counts in no sum.
TEST(Denoiser, BiasFollowsTheMeanGapRule) {
  render::FilmLayers f = randomFilm(37, 21, 5, true);
  for (float& v : f.variance) v *= 1e-4f;
  for (size_t i = 0; i < f.variance.size(); i += 7) f.variance[i] = 0.0f;  // unknown: one sample's worth
  f.samples = 100;
  f.light.assign(f.variance.size(), 0.0f);
  f.light[200] = 1.0f;
  render::FilmLayers d = randomFilm(37, 21, 6);
  // The left half close to the film (a gap the noise explains), the right half off by a common
  // factor, as a denoiser's bias along a face.
  for (size_t i = 0; i < d.combined.size(); ++i)
    d.combined[i] = f.combined[i] * ((i / 3) % size_t(f.width) < size_t(f.width / 2)
                                         ? 1.0f + 0.003f * (d.combined[i] - 1.0f)
                                         : 0.9f + 0.05f * (d.combined[i] - 1.0f));
  const std::vector<float> got = runConvergePass<render::BiasPass>(f, d.combined);
  const image::RgbImage denoised{f.width, f.height, d.combined};
  std::vector<float> want(got.size());
  size_t kept = 0, moved = 0;  // pixels other than the lamp
  const int r = gpu::denoise::kBiasRadius;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const size_t p = size_t(y) * f.width + x;
      double gap[3] = {}, sumVariance = 0, noise = 0, level = 0, count = 0;
      for (int qy = std::max(y - r, 0); qy <= std::min(y + r, f.height - 1); ++qy)
        for (int qx = std::max(x - r, 0); qx <= std::min(x + r, f.width - 1); ++qx) {
          const size_t q = size_t(qy) * f.width + qx;
          if (f.light[q] > 0) continue;
          const double w = convergeWeight(f, p, q);
          const double l = std::max(denoised.luminance(q), 0.0);
          const double v = f.variance[q] > 0 ? f.variance[q] : l * l / f.samples;
          for (int c = 0; c < 3; ++c) gap[c] += w * (double(f.combined[3 * q + c]) - d.combined[3 * q + c]);
          sumVariance += w * w * v;
          noise += w * v;
          level += w * l;
          count += w;
        }
      const double k = convergeNoiseFactor(gpu::denoise::kBiasNoiseScale, noise, level, count);
      const double g = (0.2126 * gap[0] + 0.7152 * gap[1] + 0.0722 * gap[2]) / count;
      double lambda = g != 0 ? std::clamp(1.0 - k * sumVariance / (count * count * g * g), 0.0, 1.0) : 0.0;
      if (f.light[p] > 0)
        lambda = 0;
      else {
        kept += lambda == 0.0;
        moved += lambda > 0.9;
      }
      for (int c = 0; c < 3; ++c) want[3 * p + c] = float(d.combined[3 * p + c] + lambda * gap[c] / count);
    }
  std::printf("bias 37x21: %zu pixels kept denoised, %zu moved by most of their mean gap; max abs err %.3g\n", kept,
              moved, maxAbsDiff(got, want));
  EXPECT_GT(kept, 0u);
  EXPECT_GT(moved, 0u);
  EXPECT_LT(kept + moved, size_t(f.width) * f.height - 1);  // some pixels in between
  EXPECT_EQ(got[3 * 200], d.combined[3 * 200]);
  EXPECT_LE(maxAbsDiff(got, want), 1e-4 * maxAbs(want));
}

// A non-finite film value (a NaN or Inf that reached the film) must not spread through the 5 x 5
// mean: every pixel whose window holds it keeps its denoised colour.
TEST(Denoiser, BiasKeepsANonFiniteFilmValueOut) {
  render::FilmLayers f = randomFilm(24, 20, 12, true);
  for (float& v : f.variance) v *= 1e-4f;
  f.samples = 100;
  std::vector<float> denoised(f.combined.size());
  for (size_t i = 0; i < denoised.size(); ++i) denoised[i] = 0.8f * f.combined[i];  // biased everywhere
  f.combined[3 * (10 * 24 + 10)] = INFINITY;
  f.combined[3 * (3 * 24 + 18) + 1] = NAN;
  const std::vector<float> got = runConvergePass<render::BiasPass>(f, denoised);
  size_t finite = 0, moved = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    finite += std::isfinite(got[i]);
    moved += got[i] != denoised[i];
  }
  std::printf("non-finite film values: %zu of %zu outputs finite, %zu moved\n", finite, got.size(), moved);
  EXPECT_EQ(finite, got.size());
  EXPECT_GT(moved, got.size() / 2);  // elsewhere the bias is corrected
}

// Two faces meet at an edge; the denoiser spread the bright face's light into a band three
// pixels wide on the dark face beside it, 0.7 standard deviations of the film's noise too bright
// (as on cornell's ceiling edges at 1250 spp), and got the rest right. Per pixel, no rule tells
// such a bias from noise; the band's mean gap does: with both passes the band keeps at most
// half of its squared error and of what the second pass alone keeps (most of it), and the faces
// away from the band keep the denoised level.
TEST(Denoiser, BiasRemovesABandTheNoiseHides) {
  const int w = 64, h = 48, edge = 32, band = 3;
  const float sigma = 0.01f, bias = 0.7f * sigma;
  render::FilmLayers f = film(w, h);
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, sigma);
  std::vector<float> denoised(f.combined.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float level = x < edge ? 0.5f : 0.7f;
      const float n = noise(rng);
      for (int c = 0; c < 3; ++c) {
        f.combined[3 * i + c] = level + n;
        denoised[3 * i + c] = x < edge && x >= edge - band ? level + bias : level;
      }
      f.normal[3 * i] = x < edge ? 0.0f : 1.0f;
      f.normal[3 * i + 2] = x < edge ? 1.0f : 0.0f;
      f.variance[i] = sigma * sigma;
    }
  f.samples = 1000;
  const std::vector<float> both = runBiasAndConverge(f, denoised), second = runConverge(f, denoised);
  auto bandError = [&](const std::vector<float>& img) {
    double e = 0;
    for (int y = 2; y < h - 2; ++y)
      for (int x = edge - band; x < edge; ++x) e += std::pow(img[3 * (size_t(y) * w + x)] - 0.5, 2);
    return e / ((h - 4) * band * bias * bias);
  };
  double restErr = 0, restRawErr = 0;
  for (int y = 2; y < h - 2; ++y)
    for (int x = 2; x < w - 2; ++x)
      if (x < edge - band - 2 || x > edge + 2) {
        const size_t i = size_t(y) * w + x;
        const double level = x < edge ? 0.5 : 0.7;
        restErr += std::pow(both[3 * i] - level, 2);
        restRawErr += std::pow(f.combined[3 * i] - level, 2);
      }
  std::printf("band's squared error over its bias's: both passes %.3f, the second alone %.3f; rest %.4f of the film's\n",
              bandError(both), bandError(second), restErr / restRawErr);
  EXPECT_LE(bandError(both), 0.5);
  EXPECT_LE(bandError(both), 0.5 * bandError(second));
  EXPECT_LE(restErr, 0.1 * restRawErr);
}

// The Denoiser runs the step after its filter from kConvergeMinSamples samples per pixel on, and
// not on a film of fewer, whose variance is too rough a guide.
TEST(Denoiser, ConvergesFromEnoughSamplesOnly) {
  render::FilmLayers f = randomFilm(40, 24, 9, true);
  for (float& v : f.variance) v *= 1e-3f;
  render::DenoiseSettings settings;
  settings.atrous = true;
  render::Denoiser denoiser(test::context(), settings, uint32_t(f.width), uint32_t(f.height));
  double changed[2] = {};
  for (int enough = 0; enough < 2; ++enough) {
    render::FilmLayers g = f;
    g.samples = enough ? gpu::denoise::kConvergeMinSamples : gpu::denoise::kConvergeMinSamples - 1;
    std::vector<float> filtered;
    denoiser.apply(g, &filtered);
    changed[enough] = maxAbsDiff(g.combined, filtered);
  }
  std::printf("converged against filtered: max difference %.3g below the floor, %.3g from it\n", changed[0], changed[1]);
  EXPECT_EQ(changed[0], 0.0);
  EXPECT_GT(changed[1], 0.01);
}
