// Hemisphere maps and the per-map passes: an emissive furnace gives its analytic constant map;
// the device's normalize, denoise (blur, none, U-Net) and projection agree with their CPU twins
// (tests/support/map_cpu.h) on maps traced in a real scene, the U-Net inside OSR included; the
// composite's closed-form irradiance equals the brute-force sum over texels at the map's
// normal and stays close to it at tilted normals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <utility>

#include "nn_kernels/unet_cpu.h"
#include "nn_kernels/weights.h"
#include "nn_kernels/weights_format.h"
#include "support/map_cpu.h"
#include "osr/map_tracer.h"
#include "osr/osr_test_util.h"

using namespace osr;
namespace o = osr::gpu::osr;
constexpr uint32_t kT = osr::gpu::hemi::kMapTexels;

TEST(MapTracer, EmissiveFurnaceGivesItsAnalyticConstantMap) {
  // Inside a closed box whose walls all emit Le and reflect with albedo rho, radiance is
  // Le / (1 - rho) everywhere; arriving after at least one bounce it is Le rho / (1 - rho).
  auto s = test::loadForTest(test::writeEmissiveFurnace("map_tracer"));
  oneshot::MapTracer tracer(test::context(), *s.gpu, s.bvh, s.camera, 16, 16, 7);
  std::vector<glm::uvec2> pixels = {{3, 4}, {8, 8}, {15, 1}, {0, 15}};
  auto maps = tracer.trace(pixels, 16, 1);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const float* map = maps.data() + i * o::kMapChannels * kT;
    double sum = 0, inner = 0, outer = 0;
    int nInner = 0, nOuter = 0;
    for (uint32_t t = 0; t < kT; ++t) {
      double l = map[t];  // red channel (the furnace is grey)
      EXPECT_NEAR(map[kT + t], l, 1e-4 * std::max(1.0, l));
      sum += l;
      glm::vec2 u((t % 32 + 0.5f) / 32, (t / 32 + 0.5f) / 32);
      bool rim = glm::length(2.f * u - 1.f) > 0.8f;
      (rim ? outer : inner) += l;
      (rim ? nOuter : nInner) += 1;
      float d = map[6 * kT + t];
      EXPECT_GT(d, 0.f) << "texel " << t;
      EXPECT_LT(d, 2 * std::sqrt(3.f) + 1e-3f);
      glm::vec3 n(map[3 * kT + t], map[4 * kT + t], map[5 * kT + t]);
      EXPECT_NEAR(glm::length(n), 1.f, 1e-3f);
    }
    EXPECT_NEAR(sum / kT, 1.0, 0.03) << "map " << i;
    // No angular bias: the grazing rim and the pole see the same radiance.
    EXPECT_NEAR(inner / nInner, outer / nOuter, 0.06) << "map " << i;
  }
}

namespace {

struct TracedPass {
  test::LoadedScene scene;
  oneshot::OsrIntegrator::MapDump dump;
};

// One OSR pass over cornell at 48 x 48 (r = 8: 36 maps), all maps kept for download.
oneshot::OsrIntegrator::MapDump onePass(const test::LoadedScene& s, oneshot::Denoiser d,
                                        const std::string& weights = "",
                                        std::optional<bool> byGroup = {}) {
  oneshot::OsrSettings set;
  set.denoiser = d;
  set.mapPassesByGroup = byGroup;
  set.weightsPath = weights;
  set.gridStart = set.gridMin = 8;
  set.keepAllMaps = true;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, 48, 48, set);
  test::renderOsrPasses(osr, s, 1);
  return osr.downloadMaps();
}

void expectClose(const std::vector<float>& a, const float* b, double tol, const char* what) {
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, std::abs(a[i] - b[i]) / std::max(1.0, std::abs(double(b[i]))));
  EXPECT_LT(worst, tol) << what;
}

}  // namespace

TEST(MapPasses, DenoiseAndProjectMatchCpuTwins) {
  // Both layouts of the map passes (an invocation per map, a workgroup per map) on any device:
  // normalize's statistics feed the CPU twins, denoise and project are compared with them.
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  for (auto [d, byGroup] : {std::pair{oneshot::Denoiser::None, false},
                            std::pair{oneshot::Denoiser::Blur, false},
                            std::pair{oneshot::Denoiser::None, true},
                            std::pair{oneshot::Denoiser::Blur, true}}) {
    SCOPED_TRACE(byGroup ? "a workgroup per map" : "an invocation per map");
    auto dump = onePass(s, d, "", byGroup);
    ASSERT_EQ(dump.maps, 36u);
    ASSERT_EQ(dump.oneShot.size(), size_t(36) * o::kMapChannels * kT);
    int valid = 0;
    for (uint32_t m = 0; m < dump.maps; ++m) {
      const float* shot = dump.oneShot.data() + m * o::kMapChannels * kT;
      o::MapStats stats;
      oneshot::normalizeMapCpu(shot, stats);
      auto clean = oneshot::denoiseMapCpu(d, shot, nullptr, stats);
      expectClose(clean, dump.clean.data() + m * 3 * kT, 1e-4, oneshot::denoiserName(d));
      glm::vec3 mean;
      std::array<glm::vec3, 9> sh;
      oneshot::projectMapCpu(dump.clean.data() + m * 3 * kT, mean, sh);
      const auto& rec = dump.projections[m];
      valid += dump.points[m].position.w > 0.5f;
      EXPECT_LT(glm::length(glm::vec3(rec.mean) - mean), 1e-4f * (1 + glm::length(mean)));
      for (int i = 0; i < 9; ++i)
        EXPECT_LT(glm::length(glm::vec3(rec.sh[i]) - sh[i]), 1e-3f * (1 + glm::length(sh[0])));
    }
    EXPECT_GT(valid, 30);
  }
}

// The test network's file with its header's normalization renamed (header length and checksum
// rewritten; the data offset has room for the longer name).
std::string withNormalization(const std::string& weights, const std::string& normalization) {
  std::ifstream in(weights, std::ios::binary);
  std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), {});
  uint64_t headerBytes = 0;
  std::memcpy(&headerBytes, file.data() + nn::kOffsetHeaderBytes, 8);
  std::string header(file.begin() + nn::kPrefixBytes, file.begin() + nn::kPrefixBytes + headerBytes);
  const std::string from = std::string("\"") + nn::kNormalizationLogMean10 + "\"";
  header.replace(header.find(from), from.size(), "\"" + normalization + "\"");
  uint64_t dataOffset = 0;
  std::memcpy(&dataOffset, file.data() + nn::kOffsetDataOffset, 8);
  EXPECT_LE(nn::kPrefixBytes + header.size(), dataOffset);
  std::fill(file.begin() + nn::kPrefixBytes, file.begin() + dataOffset, 0);
  std::copy(header.begin(), header.end(), file.begin() + nn::kPrefixBytes);
  headerBytes = header.size();
  std::memcpy(file.data() + nn::kOffsetHeaderBytes, &headerBytes, 8);
  uint32_t crc = nn::crc32(file.data() + nn::kPrefixBytes, file.size() - nn::kPrefixBytes);
  std::memcpy(file.data() + nn::kOffsetChecksum, &crc, 4);
  std::string path = (test::tempDir("map_tracer") / ("unet_" + normalization + ".osrw")).string();
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(file.data()), file.size());
  return path;
}

TEST(MapPasses, UnetInsideOsrMatchesTheCpuNetwork) {
  // The packed random-weight test network (K = 8): normalize -> U-Net -> denormalize on the
  // device equals the CPU twins and the CPU U-Net on the same one-shot maps, with the output
  // rescaled to the one-shot channel means and taken as predicted (absolute).
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  const std::string rescaled = test::dataPath("unet_k8.osrw");
  const std::string absolute = withNormalization(rescaled, nn::kNormalizationLogMean10Absolute);
  // The rescaled output's mean is a workgroup's sum in the GPU layout: checked in both layouts.
  struct Case {
    std::string weights;
    uint32_t netOutput;
    bool byGroup;
  };
  for (const auto& [weights, netOutput, byGroup] :
       {Case{rescaled, o::kNetOutputRescaled, false}, Case{rescaled, o::kNetOutputRescaled, true},
        Case{absolute, o::kNetOutputAbsolute, false}}) {
    SCOPED_TRACE(byGroup ? "a workgroup per map" : "an invocation per map");
    auto dump = onePass(s, oneshot::Denoiser::Unet, weights, byGroup);
    auto w = nn::UNetWeights::load(weights);
    const uint32_t n = 6;  // maps checked (the CPU network is slow)
    nn::Tensor in(n, o::kMapChannels, 32, 32);
    std::vector<o::MapStats> stats(n);
    for (uint32_t m = 0; m < n; ++m) {
      auto norm = oneshot::normalizeMapCpu(dump.oneShot.data() + m * o::kMapChannels * kT, stats[m]);
      std::copy(norm.begin(), norm.end(), in.data.begin() + m * o::kMapChannels * kT);
    }
    nn::Tensor out = nn::unetCpu(w, in);
    for (uint32_t m = 0; m < n; ++m) {
      auto clean = oneshot::denoiseMapCpu(oneshot::Denoiser::Unet,
                                          dump.oneShot.data() + m * o::kMapChannels * kT,
                                          out.data.data() + m * 3 * kT, stats[m], netOutput);
      expectClose(clean, dump.clean.data() + m * 3 * kT, 2e-3, weights.c_str());
    }
  }
}

TEST(MapPasses, ClosedFormIrradianceMatchesBruteForce) {
  auto s = test::loadForTest(test::referencePath("cornell/cornell.gltf"));
  auto dump = onePass(s, oneshot::Denoiser::Blur);
  for (uint32_t m = 0; m < dump.maps; ++m) {
    if (dump.points[m].position.w < 0.5f) continue;
    const float* clean = dump.clean.data() + m * 3 * kT;
    glm::vec3 mean;
    std::array<glm::vec3, 9> sh;
    oneshot::projectMapCpu(clean, mean, sh);
    // At the map's own normal: exact.
    glm::vec3 exact = oneshot::bruteForceIrradiance(clean, {0, 0, 1});
    glm::vec3 closed = oneshot::mapIrradianceCpu(mean, sh, {0, 0, 1});
    EXPECT_LT(glm::length(closed - exact), 1e-4f * (1 + glm::length(exact))) << "map " << m;
    // Tilted by about 15 degrees: the SH correction stays within 10% of the sum.
    glm::vec3 n = glm::normalize(glm::vec3(0.26f, 0.f, 0.97f));
    glm::vec3 tilted = oneshot::bruteForceIrradiance(clean, n);
    glm::vec3 approx = oneshot::mapIrradianceCpu(mean, sh, n);
    EXPECT_LT(glm::length(approx - tilted), 0.1f * glm::length(tilted) + 1e-4f) << "map " << m;
  }
}
