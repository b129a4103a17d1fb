#include "support/map_cpu.h"

#include <algorithm>
#include <cmath>

namespace osr::oneshot {

namespace o = gpu::osr;
namespace hemi = gpu::hemi;

namespace {
constexpr uint32_t kT = hemi::kMapTexels;
constexpr double kPi = 3.14159265358979323846;

glm::vec3 texelDirection(uint32_t t) {
  glm::vec2 u((t % hemi::kMapSize + 0.5f) / hemi::kMapSize,
              (t / hemi::kMapSize + 0.5f) / hemi::kMapSize);
  return hemi::hemiSquareToDirection(u);
}

std::array<double, 9> shBasis(glm::vec3 d) {
  return {0.282095,
          0.488603 * d.y,
          0.488603 * d.z,
          0.488603 * d.x,
          1.092548 * d.x * d.y,
          1.092548 * d.y * d.z,
          0.315392 * (3.0 * d.z * d.z - 1.0),
          1.092548 * d.x * d.z,
          0.546274 * (d.x * d.x - d.y * d.y)};
}
}  // namespace

std::vector<float> normalizeMapCpu(const float* m, o::MapStats& stats) {
  double sum[3] = {0, 0, 0}, dist = 0;
  for (uint32_t t = 0; t < kT; ++t) {
    for (int c = 0; c < 3; ++c) sum[c] += m[c * kT + t];
    dist += m[6 * kT + t];
  }
  glm::vec3 mean(float(sum[0] / kT), float(sum[1] / kT), float(sum[2] / kT));
  float meanAll = (mean.r + mean.g + mean.b) / 3.f;
  float meanDist = float(dist / kT);
  stats.meanRadiance = glm::vec4(mean, meanAll);
  stats.meanDistance = glm::vec4(meanDist, 0, 0, 0);
  std::vector<float> out(o::kMapChannels * kT);
  for (uint32_t t = 0; t < kT; ++t) {
    for (int c = 0; c < 3; ++c) out[c * kT + t] = o::normalizeRadiance(m[c * kT + t], meanAll);
    for (int c = 3; c < 6; ++c) out[c * kT + t] = m[c * kT + t];
    out[6 * kT + t] = o::normalizeDistance(m[6 * kT + t], meanDist);
  }
  return out;
}

std::vector<float> denoiseMapCpu(Denoiser d, const float* oneShot, const float* netOut,
                                 const o::MapStats& stats, uint32_t netOutput) {
  const bool absolute = d == Denoiser::Unet && netOutput == o::kNetOutputAbsolute;
  std::vector<float> out(3 * kT);
  const double g[3] = {0.40262, 0.24420, 0.05448};
  for (int c = 0; c < 3; ++c) {
    std::vector<double> v(kT);
    for (uint32_t t = 0; t < kT; ++t) {
      if (d == Denoiser::None) {
        v[t] = oneShot[c * kT + t];
      } else if (d == Denoiser::Unet) {
        v[t] = std::max(0.0, std::exp(std::min<double>(netOut[c * kT + t], 80.0)) - 1.0);
      } else {
        int x = int(t % 32), y = int(t / 32);
        double s = 0, ws = 0;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            int sx = x + dx, sy = y + dy;
            if (sx < 0 || sy < 0 || sx >= 32 || sy >= 32) continue;
            s += g[std::abs(dx)] * g[std::abs(dy)] * oneShot[c * kT + sy * 32 + sx];
            ws += g[std::abs(dx)] * g[std::abs(dy)];
          }
        v[t] = std::max(0.0, s / ws);
      }
    }
    double mean = 0;
    for (double x : v) mean += x / kT;
    for (uint32_t t = 0; t < kT; ++t) {
      if (d == Denoiser::None)
        out[c * kT + t] = float(v[t]);
      else if (absolute)
        out[c * kT + t] = float(10.0 * stats.meanRadiance.w * v[t]);
      else
        out[c * kT + t] =
            mean > 0 ? float(v[t] * stats.meanRadiance[c] / mean) : stats.meanRadiance[c];
    }
  }
  return out;
}

void projectMapCpu(const float* clean, glm::vec3& mean, std::array<glm::vec3, 9>& sh) {
  std::array<glm::dvec3, 9> acc{};
  glm::dvec3 sum(0.0);
  for (uint32_t t = 0; t < kT; ++t) {
    glm::dvec3 l(clean[t], clean[kT + t], clean[2 * kT + t]);
    sum += l;
    glm::vec3 w = texelDirection(t);
    double dOmega = kPi / (kT * std::max(double(w.z), 1e-3));
    auto y = shBasis(w);
    for (int i = 0; i < 9; ++i) acc[i] += l * (y[i] * dOmega);
  }
  const double a[3] = {kPi, 2 * kPi / 3, kPi / 4};
  for (int i = 0; i < 9; ++i) sh[i] = glm::vec3(acc[i] * a[i == 0 ? 0 : i < 4 ? 1 : 2]);
  mean = glm::vec3(sum / double(kT));
}

glm::vec3 mapIrradianceCpu(const glm::vec3& mean, const std::array<glm::vec3, 9>& sh, glm::vec3 n) {
  auto eval = [&](glm::vec3 d) {
    auto y = shBasis(d);
    glm::dvec3 e(0.0);
    for (int i = 0; i < 9; ++i) e += glm::dvec3(sh[i]) * y[i];
    return e;
  };
  glm::dvec3 e = kPi * glm::dvec3(mean) + eval(n) - eval(glm::vec3(0, 0, 1));
  return glm::vec3(glm::max(e, glm::dvec3(0.0)));
}

glm::vec3 bruteForceIrradiance(const float* clean, glm::vec3 n) {
  glm::dvec3 e(0.0);
  for (uint32_t t = 0; t < kT; ++t) {
    glm::vec3 w = texelDirection(t);
    double cosN = std::max(0.0, double(glm::dot(w, n)));
    // Projected solid angle pi / 1024 about the map normal, so d(omega) = that / cos.
    double dOmega = kPi / (kT * std::max(double(w.z), 1e-3));
    e += glm::dvec3(clean[t], clean[kT + t], clean[2 * kT + t]) * (cosN * dOmega);
  }
  return glm::vec3(e);
}

}  // namespace osr::oneshot
