// shared/hemisphere.h: the cosine-concentric mapping round-trips (square -> direction ->
// square), every texel of a 32 x 32 map covers the same projected solid angle, the frame is
// orthonormal with z = n, the 8 symmetries of the square act on directions as rotations and
// reflections about z, and the GLSL (osr_hemisphere_probe.comp) agrees with the C++ twin.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "common/vk_test.h"
#include "shaders/shared/hemisphere.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

using namespace osr;
namespace hemi = osr::gpu::hemi;

TEST(Hemisphere, RoundTripSquareToDirectionToSquare) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 100000; ++i) {
    glm::vec2 s(u(rng), u(rng));
    glm::vec3 d = hemi::hemiSquareToDirection(s);
    ASSERT_NEAR(glm::length(d), 1.f, 1e-5f);
    ASSERT_GE(d.z, 0.f);
    glm::vec2 back = hemi::hemiDirectionToSquare(d);
    ASSERT_NEAR(back.x, s.x, 2e-4f) << s.x << " " << s.y;
    ASSERT_NEAR(back.y, s.y, 2e-4f) << s.x << " " << s.y;
  }
}

TEST(Hemisphere, TexelsCoverEqualProjectedSolidAngle) {
  // Cosine-distributed directions drawn by another method (Malley, polar disk) land uniformly
  // on the 1024 texels.
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 1 << 22;
  std::vector<int> counts(hemi::kMapTexels, 0);
  for (int i = 0; i < n; ++i) {
    double r = std::sqrt(u(rng)), phi = 2 * M_PI * u(rng);
    glm::vec3 d(float(r * std::cos(phi)), float(r * std::sin(phi)),
                float(std::sqrt(std::max(0.0, 1 - r * r))));
    glm::vec2 s = hemi::hemiDirectionToSquare(d);
    int x = std::min(31, int(s.x * 32)), y = std::min(31, int(s.y * 32));
    counts[y * 32 + x]++;
  }
  const double expected = double(n) / hemi::kMapTexels, sigma = std::sqrt(expected);
  for (uint32_t t = 0; t < hemi::kMapTexels; ++t)
    EXPECT_NEAR(counts[t], expected, 5 * sigma) << "texel " << t;
}

TEST(Hemisphere, SymmetriesOfTheSquareRotateAndReflectDirections) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 1000; ++i) {
    glm::vec2 s(u(rng), u(rng));
    glm::vec3 d = hemi::hemiSquareToDirection(s);
    // 90 degrees counter-clockwise about the square's centre: (x, y) -> (1 - y, x).
    glm::vec3 r = hemi::hemiSquareToDirection(glm::vec2(1.f - s.y, s.x));
    EXPECT_NEAR(r.x, -d.y, 1e-5f);
    EXPECT_NEAR(r.y, d.x, 1e-5f);
    EXPECT_NEAR(r.z, d.z, 1e-5f);
    glm::vec3 m = hemi::hemiSquareToDirection(glm::vec2(1.f - s.x, s.y));
    EXPECT_NEAR(m.x, -d.x, 1e-5f);
    EXPECT_NEAR(m.y, d.y, 1e-5f);
  }
}

TEST(Hemisphere, FrameIsOrthonormalWithZAlongTheNormal) {
  std::mt19937 rng(4);
  std::normal_distribution<float> g;
  for (int i = 0; i < 10000; ++i) {
    glm::vec3 n = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    glm::mat3 f = hemi::hemiFrame(n);
    EXPECT_NEAR(glm::dot(f[0], f[1]), 0.f, 1e-5f);
    EXPECT_NEAR(glm::length(f[0]), 1.f, 1e-5f);
    EXPECT_NEAR(glm::length(f[1]), 1.f, 1e-5f);
    EXPECT_NEAR(glm::length(f[2] - n), 0.f, 1e-6f);
    EXPECT_NEAR(glm::dot(glm::cross(f[0], f[1]), n), 1.f, 1e-5f);  // right-handed
  }
}

namespace {
// The GPU's hemiSquareToDirection agrees with the C++ twin's `cpu` within what Vulkan lets a
// device's arithmetic differ ("Precision and Operation of SPIR-V Instructions", GLSL.std.450
// table): sin and cos each within 2^-11 absolute on [-pi, pi] (theta lies in [-pi/4, 3pi/4]),
// so the disk point (x, y) = r (cos, sin), r <= 1, within sqrt(2) 2^-11; the division that
// makes theta (2.5 ulp) and the products add ulps, 1e-6 covers them. z = sqrt(1 - x^2 - y^2)
// is compared as z^2: near the rim dz = -(x dx + y dy) / z grows without bound (case 3899,
// z = 0.0107, r = 0.99994: an NVIDIA H200's direction was 1.6e-5 off, what (x, y) 1.7e-7
// farther out makes there),
// while z^2 moves by at most 2 |(x, y)| e + e^2 for a disk error e, plus the rounding of
// 1 - x^2 - y^2 and of sqrt (1 / inversesqrt: 2 ulp and 2.5 ulp), under 1e-6. A wrong mapping
// (swapped or mirrored axes, a lost sqrt) is off by order 1 and fails.
bool directionAgrees(glm::vec3 gpu, glm::vec3 cpu) {
  const float disk = std::sqrt(2.0f) * std::ldexp(1.0f, -11) + 1e-6f;
  return glm::length(glm::vec2(gpu) - glm::vec2(cpu)) < disk && gpu.z >= 0.0f &&
         std::abs(gpu.z * gpu.z - cpu.z * cpu.z) < 2.0f * disk + disk * disk + 1e-6f;
}
}  // namespace

TEST(Hemisphere, GpuMatchesCpp) {
  auto& ctx = test::context();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g;
  std::vector<hemi::HemiProbeCase> cases(4099);
  for (auto& c : cases) {
    c.square = glm::vec4(u(rng), u(rng), 0, 0);
    glm::vec3 d = glm::normalize(glm::vec3(g(rng), g(rng), std::abs(g(rng))));
    c.direction = glm::vec4(d, 0);
    c.normal = glm::vec4(glm::normalize(glm::vec3(g(rng), g(rng), g(rng))), 0);
  }
  cases[0].square = glm::vec4(0.5f, 0.5f, 0, 0);  // the centre (the pole)
  cases[1].direction = glm::vec4(0, 0, 1, 0);
  cases[2].normal = glm::vec4(0, 0, -1, 0);  // the frame's sign switch
  vk::Buffer buf(ctx, cases.size() * sizeof(hemi::HemiProbeCase), vk::MemoryUse::DeviceLocal,
                 "hemisphere probe");
  buf.uploadVector(cases);
  vk::ComputePipeline pipe(ctx, shaders::Id::osr_hemisphere_probe, 1, sizeof(uint32_t));
  uint32_t count = uint32_t(cases.size());
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    vk::Binder(pipe).set(hemi::kHemiProbeBindingCases, buf).bind(cmd, count);
    pipe.dispatch(cmd, vk::groupCount(count, hemi::kHemiProbeWorkgroupSize));
  });
  auto out = buf.downloadVector<hemi::HemiProbeCase>(cases.size());
  size_t swappedCaught = 0, mirroredCaught = 0, sqrtLostCaught = 0;
  for (size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    glm::vec3 d = hemi::hemiSquareToDirection(glm::vec2(c.square));
    glm::vec2 back = hemi::hemiDirectionToSquare(d);
    glm::vec2 s = hemi::hemiDirectionToSquare(glm::vec3(c.direction));
    glm::mat3 f = hemi::hemiFrame(glm::vec3(c.normal));
    ASSERT_TRUE(directionAgrees(glm::vec3(out[i].toDirection), d))
        << "case " << i << ": gpu " << out[i].toDirection.x << " " << out[i].toDirection.y << " "
        << out[i].toDirection.z << ", c++ " << d.x << " " << d.y << " " << d.z;
    // The check itself: wrong mappings of the same square fail it.
    swappedCaught += !directionAgrees(glm::vec3(d.y, d.x, d.z), d);
    mirroredCaught += !directionAgrees(glm::vec3(-d.x, d.y, d.z), d);
    sqrtLostCaught += !directionAgrees(glm::vec3(d.x, d.y, d.z * d.z), d);
    ASSERT_LT(glm::length(glm::vec2(out[i].square.z, out[i].square.w) - back), 1e-4f) << i;
    ASSERT_LT(glm::length(glm::vec2(out[i].toSquare) - s), 1e-4f) << "case " << i;
    ASSERT_LT(glm::length(glm::vec3(out[i].frameT) - f[0]), 1e-5f) << "case " << i;
    ASSERT_LT(glm::length(glm::vec3(out[i].frameB) - f[1]), 1e-5f) << "case " << i;
  }
  EXPECT_GT(swappedCaught, cases.size() * 99 / 100);
  EXPECT_GT(mirroredCaught, cases.size() * 99 / 100);
  EXPECT_GT(sqrtLostCaught, cases.size() * 99 / 100);
  std::printf("wrong mappings caught: swapped axes %zu, mirrored x %zu, lost sqrt %zu of %zu\n", swappedCaught,
              mirroredCaught, sqrtLostCaught, cases.size());
}
