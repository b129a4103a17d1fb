// shared/hemisphere.h: the cosine-concentric mapping round-trips (square -> direction ->
// square), every texel of a 32 x 32 map covers the same projected solid angle, the frame is
// orthonormal with z = n, the 8 symmetries of the square act on directions as rotations and
// reflections about z, and the GLSL (osr_hemisphere_probe.comp) agrees with the C++ twin.
#include <gtest/gtest.h>

#include <cmath>
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
  for (size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    glm::vec3 d = hemi::hemiSquareToDirection(glm::vec2(c.square));
    glm::vec2 back = hemi::hemiDirectionToSquare(d);
    glm::vec2 s = hemi::hemiDirectionToSquare(glm::vec3(c.direction));
    glm::mat3 f = hemi::hemiFrame(glm::vec3(c.normal));
    ASSERT_LT(glm::length(glm::vec3(out[i].toDirection) - d), 1e-5f) << "case " << i;
    ASSERT_LT(glm::length(glm::vec2(out[i].square.z, out[i].square.w) - back), 1e-4f) << i;
    ASSERT_LT(glm::length(glm::vec2(out[i].toSquare) - s), 1e-4f) << "case " << i;
    ASSERT_LT(glm::length(glm::vec3(out[i].frameT) - f[0]), 1e-5f) << "case " << i;
    ASSERT_LT(glm::length(glm::vec3(out[i].frameB) - f[1]), 1e-5f) << "case " << i;
  }
}
