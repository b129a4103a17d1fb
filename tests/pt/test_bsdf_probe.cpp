// shaders/lib/bsdf.glsl through pt_bsdf_probe.comp: sampling and evaluation agree (the sampled
// albedo estimate equals the albedo integrated numerically from bsdfEval, bsdfEval's pdf
// integrates to the fraction of valid samples, so sampling draws the density it reports), a
// Lambertian material is exactly baseColor / pi, and a smooth white dielectric conserves energy.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "common/vk_test.h"
#include "support/bsdf_probe.h"

using namespace osr;
namespace probe = osr::gpu::bsdf;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr uint32_t kTheta = 192, kPhi = 384;
constexpr uint32_t kSamples = 1u << 16;

probe::ProbeCase makeCase(glm::vec3 base, float metallic, float roughness, float thetaDeg,
                          float transmission = 0.f, float eta = 1.5f,
                          glm::vec3 specColor = {1, 1, 1}, float specular = 1.f) {
  probe::ProbeCase c{};
  c.params.baseColor = base;
  c.params.metallic = metallic;
  c.params.specularColor = specColor;
  c.params.roughness = roughness;
  c.params.specular = specular;
  c.params.eta = eta;
  c.params.transmission = transmission;
  float t = thetaDeg * float(kPi) / 180.f;
  c.wo = glm::vec4(std::sin(t), 0.f, std::cos(t), 0.f);
  return c;
}

std::string describe(const probe::ProbeCase& c) {
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "base (%g %g %g) metallic %g roughness %g transmission %g eta %g wo.z %g",
                c.params.baseColor.x, c.params.baseColor.y, c.params.baseColor.z, c.params.metallic,
                c.params.roughness, c.params.transmission, c.params.eta, c.wo.z);
  return buf;
}

struct Quadrature {
  glm::dvec3 albedo{0.0};
  double pdfMass = 0.0;
};

std::vector<Quadrature> integrate(const pt::BsdfProbe& p,
                                  const std::vector<probe::ProbeCase>& cases) {
  probe::ProbePush push{probe::kProbeEval, 0, kTheta, kPhi, 0, 0};
  auto out = p.run(cases, push);
  std::vector<Quadrature> q(cases.size());
  double dTheta = kPi / kTheta, dPhi = 2 * kPi / kPhi;
  for (size_t c = 0; c < cases.size(); ++c)
    for (uint32_t it = 0; it < kTheta; ++it) {
      double w = std::sin((it + 0.5) * dTheta) * dTheta * dPhi;
      for (uint32_t ip = 0; ip < kPhi; ++ip) {
        const auto& o = out[(c * kTheta + it) * kPhi + ip];
        q[c].albedo += glm::dvec3(o.value) * w;
        q[c].pdfMass += o.pdf * w;
      }
    }
  return q;
}

struct Sampled {
  glm::dvec3 mean{0.0};
  glm::dvec3 stderr_{0.0};
  double validFraction = 0.0;  // valid continuous samples
  bool finite = true;
};

std::vector<Sampled> sample(const pt::BsdfProbe& p,
                            const std::vector<probe::ProbeCase>& cases) {
  probe::ProbePush push{probe::kProbeSample, 0, 0, 0, kSamples, 7};
  auto out = p.run(cases, push);
  std::vector<Sampled> s(cases.size());
  for (size_t c = 0; c < cases.size(); ++c) {
    glm::dvec3 sum(0.0), sum2(0.0);
    uint32_t valid = 0;
    for (uint32_t i = 0; i < kSamples; ++i) {
      const auto& o = out[c * kSamples + i];
      glm::dvec3 v(o.value);
      if (!std::isfinite(v.x + v.y + v.z + o.pdf)) s[c].finite = false;
      sum += v;
      sum2 += v * v;
      bool ok = o.flags & 2u, delta = o.flags & 1u;
      if (ok && !delta) ++valid;
    }
    s[c].mean = sum / double(kSamples);
    glm::dvec3 var = sum2 / double(kSamples) - s[c].mean * s[c].mean;
    s[c].stderr_ = glm::sqrt(glm::max(var, glm::dvec3(0.0)) / double(kSamples));
    s[c].validFraction = double(valid) / kSamples;
  }
  return s;
}

}  // namespace

TEST(BsdfProbe, SampledAlbedoMatchesIntegratedAlbedo) {
  pt::BsdfProbe p(test::context());
  std::vector<probe::ProbeCase> cases;
  glm::vec3 base(0.8f, 0.5f, 0.2f);
  for (float rough : {0.3f, 0.6f, 1.0f})
    for (float metal : {0.f, 0.5f, 1.f})
      for (float theta : {0.f, 45.f, 75.f}) cases.push_back(makeCase(base, metal, rough, theta));
  // Rough glass from outside and from inside (eta < 1: total internal reflection happens).
  for (float rough : {0.3f, 0.7f})
    for (float theta : {10.f, 60.f}) {
      cases.push_back(makeCase(glm::vec3(1.f), 0.f, rough, theta, 1.f, 1.5f));
      cases.push_back(makeCase(glm::vec3(1.f), 0.f, rough, theta, 1.f, 1.f / 1.5f));
    }
  // A partly transmissive, partly metallic mix with a tinted specular layer.
  cases.push_back(makeCase(base, 0.3f, 0.5f, 30.f, 0.5f, 1.33f, {0.5f, 1.f, 0.8f}, 0.7f));
  for (size_t first = 0; first < cases.size(); first += 8) {
    std::vector<probe::ProbeCase> batch(cases.begin() + first,
                                        cases.begin() + std::min(cases.size(), first + 8));
    auto q = integrate(p, batch);
    auto s = sample(p, batch);
    for (size_t c = 0; c < batch.size(); ++c) {
      SCOPED_TRACE(describe(batch[c]));
      EXPECT_TRUE(s[c].finite);
      for (int k = 0; k < 3; ++k) {
        // 5 standard errors of the Monte Carlo estimate plus 0.5% for the quadrature grid.
        double tol = 5.0 * s[c].stderr_[k] + 0.005 * q[c].albedo[k] + 1e-4;
        EXPECT_NEAR(s[c].mean[k], q[c].albedo[k], tol) << "channel " << k;
        EXPECT_LE(q[c].albedo[k], 1.0 + 0.01) << "channel " << k << ": gains energy";
      }
      EXPECT_NEAR(q[c].pdfMass, s[c].validFraction, 0.01 + 0.005);
    }
  }
}

TEST(BsdfProbe, LambertianIsBaseColorOverPi) {
  pt::BsdfProbe p(test::context());
  // What Blender's exporter writes for a Diffuse BSDF: specular colour 0, roughness 1.
  glm::vec3 base(0.63f, 0.065f, 0.05f);
  std::vector<probe::ProbeCase> cases = {
      makeCase(base, 0.f, 1.f, 0.f, 0.f, 1.45f, glm::vec3(0.f)),
      makeCase(base, 0.f, 1.f, 70.f, 0.f, 1.45f, glm::vec3(0.f))};
  probe::ProbePush push{probe::kProbeEval, 0, 32, 64, 0, 0};
  auto out = p.run(cases, push);
  for (const auto& o : out) {
    float cosine = std::max(0.f, o.wi.z);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(o.value[k], base[k] / kPi * cosine, 1e-6);
    ASSERT_NEAR(o.pdf, cosine / kPi, 1e-6);
  }
  auto s = sample(p, cases);
  for (const auto& x : s)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(x.mean[k], base[k], 1e-5);  // weight is exact
}

TEST(BsdfProbe, SmoothWhiteDielectricConservesEnergy) {
  pt::BsdfProbe p(test::context());
  std::vector<probe::ProbeCase> cases;
  for (float eta : {1.5f, 1.f / 1.5f})
    for (float theta : {0.f, 30.f, 60.f, 85.f})
      cases.push_back(makeCase(glm::vec3(1.f), 0.f, 0.f, theta, 1.f, eta));
  auto s = sample(p, cases);
  for (size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE(describe(cases[c]));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[c].mean[k], 1.0, 1e-5);
  }
  // A smooth interface has no continuous part: its eval is zero everywhere.
  auto q = integrate(p, {cases[0]});
  EXPECT_EQ(q[0].pdfMass, 0.0);
}
