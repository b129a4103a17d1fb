// shaders/lib/bsdf.glsl through pt_bsdf_probe.comp: sampling and evaluation agree (the sampled
// albedo estimate equals the albedo integrated numerically from bsdfEval, bsdfEval's pdf
// integrates to the fraction of valid samples, and a chi-square test of the sampled directions
// against bsdfEval's pdf, as pbrt-v4 and Mitsuba test their BSDFs), a Lambertian material is
// exactly baseColor / pi, a smooth white dielectric conserves energy, and the layered lobes
// (clearcoat, sheen, diffuse transmission, anisotropy, iridescence) keep white furnaces at or
// below 1, at 1 where the lobe conserves energy. The thin-film Fresnel (shared/thin_film.h) is
// also checked on the host.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/vk_test.h"
#include "shaders/shared/thin_film.h"
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
  c.params.clearcoatNormal = {0, 0, 1};
  c.params.diffuseTransmissionColor = {1, 1, 1};
  c.params.anisotropyDirection = {1, 0};
  c.params.iridescenceIor = 1.3f;
  float t = thetaDeg * float(kPi) / 180.f;
  c.wo = glm::vec4(std::sin(t), 0.f, std::cos(t), 0.f);
  return c;
}

std::string describe(const probe::ProbeCase& c) {
  char buf[480];
  std::snprintf(buf, sizeof buf,
                "base (%g %g %g) metallic %g roughness %g transmission %g eta %g wo (%g %g %g) "
                "coat %g/%g n (%g %g %g) sheen %g/%g dt %g aniso %g dir (%g %g) "
                "film %g ior %g %g nm",
                c.params.baseColor.x, c.params.baseColor.y, c.params.baseColor.z, c.params.metallic,
                c.params.roughness, c.params.transmission, c.params.eta, c.wo.x, c.wo.y, c.wo.z,
                c.params.clearcoat, c.params.clearcoatRoughness, c.params.clearcoatNormal.x,
                c.params.clearcoatNormal.y, c.params.clearcoatNormal.z, c.params.sheenColor.x,
                c.params.sheenRoughness, c.params.diffuseTransmission, c.params.anisotropy,
                c.params.anisotropyDirection.x, c.params.anisotropyDirection.y,
                c.params.iridescence, c.params.iridescenceIor, c.params.iridescenceThickness);
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

// The denoisers' albedo guide (denoiseAlbedo) is what the surface reflects of uniform light:
// the albedo integrated from bsdfEval, for matte and glossy dielectrics of dark and light
// base colours and rough metals, at normal and grazing views, within 30 % (its GGX part is a
// fit, low by up to a quarter at 75 degrees, where the base colour alone can be a sixth of it).
// Divided by it, a tiled glossy floor's light hardly changes with the tiles' colour; a
// Lambertian's guide is its base colour.
TEST(BsdfProbe, DenoiseAlbedoIsTheDirectionalAlbedo) {
  pt::BsdfProbe p(test::context());
  std::vector<probe::ProbeCase> cases;
  for (glm::vec3 base : {glm::vec3(0.05f, 0.1f, 0.4f), glm::vec3(0.1f, 0.4f, 0.1f), glm::vec3(0.8f)})
    for (float roughness : {0.2f, 0.5f, 0.9f})
      for (float theta : {0.f, 45.f, 75.f}) cases.push_back(makeCase(base, 0.f, roughness, theta));
  for (float roughness : {0.3f, 0.6f})
    for (float theta : {0.f, 60.f})
      cases.push_back(makeCase(glm::vec3(0.9f, 0.6f, 0.3f), 1.f, roughness, theta));
  glm::vec3 lambertBase(0.63f, 0.065f, 0.05f);
  cases.push_back(makeCase(lambertBase, 0.f, 1.f, 30.f, 0.f, 1.45f, glm::vec3(0.f)));
  auto q = integrate(p, cases);
  auto guide = p.run(cases, probe::ProbePush{probe::kProbeGuide, 0, 0, 0, 0, 0});
  double worst = 0.0;
  for (size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE(describe(cases[c]));
    for (int k = 0; k < 3; ++k) {
      double rel = std::abs(guide[c].value[k] - q[c].albedo[k]) / (q[c].albedo[k] + 0.02);
      worst = std::max(worst, rel);
      EXPECT_LT(rel, 0.3) << "channel " << k << ": guide " << guide[c].value[k] << ", albedo "
                           << q[c].albedo[k];
    }
  }
  std::printf("denoiseAlbedo against the integrated albedo: worst |difference| / (albedo + 0.02) %.3f\n", worst);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(guide.back().value[k], lambertBase[k]);
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

// ---- Layered lobes ------------------------------------------------------------------------

namespace {

probe::ProbeCase coat(probe::ProbeCase c, float weight, float roughness,
                      glm::vec3 normal = {0, 0, 1}) {
  c.params.clearcoat = weight;
  c.params.clearcoatRoughness = roughness;
  c.params.clearcoatNormal = glm::normalize(normal);
  return c;
}
probe::ProbeCase sheen(probe::ProbeCase c, glm::vec3 color, float roughness) {
  c.params.sheenColor = color;
  c.params.sheenRoughness = roughness;
  return c;
}
probe::ProbeCase diffuseTransmission(probe::ProbeCase c, float factor, glm::vec3 color) {
  c.params.diffuseTransmission = factor;
  c.params.diffuseTransmissionColor = color;
  return c;
}
probe::ProbeCase anisotropy(probe::ProbeCase c, float strength, float rotation) {
  c.params.anisotropy = strength;
  c.params.anisotropyDirection = {std::cos(rotation), std::sin(rotation)};
  return c;
}

probe::ProbeCase film(probe::ProbeCase c, float factor, float ior, float thicknessNm) {
  c.params.iridescence = factor;
  c.params.iridescenceIor = ior;
  c.params.iridescenceThickness = thicknessNm;
  return c;
}

// Chi-square statistic of the sampled directions against bsdfEval's pdf on a coarse
// (theta, phi) binning of the sphere, bins with fewer than 5 expected samples pooled (pbrt-v4's
// rule), and its p-value by the Wilson-Hilferty approximation of the chi-square distribution.
struct ChiSquare {
  double statistic = 0.0;
  int dof = 0;
  double pValue = 1.0;
};

ChiSquare chiSquare(const std::vector<probe::ProbeOut>& eval, const std::vector<probe::ProbeOut>& samples,
                    size_t c) {
  constexpr uint32_t kBinTheta = 16, kBinPhi = 32;
  std::vector<double> expected(kBinTheta * kBinPhi, 0.0), observed(kBinTheta * kBinPhi, 0.0);
  double dTheta = kPi / kTheta, dPhi = 2 * kPi / kPhi;
  for (uint32_t it = 0; it < kTheta; ++it)
    for (uint32_t ip = 0; ip < kPhi; ++ip) {
      const auto& o = eval[(c * kTheta + it) * kPhi + ip];
      double w = std::sin((it + 0.5) * dTheta) * dTheta * dPhi;
      expected[(it * kBinTheta / kTheta) * kBinPhi + ip * kBinPhi / kPhi] += o.pdf * w * kSamples;
    }
  for (uint32_t i = 0; i < kSamples; ++i) {
    const auto& o = samples[c * kSamples + i];
    if (!(o.flags & 2u) || (o.flags & 1u)) continue;
    double theta = std::acos(std::clamp(double(o.wi.z), -1.0, 1.0));
    double phi = std::atan2(double(o.wi.y), double(o.wi.x));
    if (phi < 0) phi += 2 * kPi;
    uint32_t bt = std::min(kBinTheta - 1, uint32_t(theta / kPi * kBinTheta));
    uint32_t bp = std::min(kBinPhi - 1, uint32_t(phi / (2 * kPi) * kBinPhi));
    observed[bt * kBinPhi + bp] += 1.0;
  }
  std::vector<size_t> order(expected.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  ChiSquare r;
  double pooledE = 0.0, pooledO = 0.0;
  for (size_t i : order) {
    if (expected[i] < 5.0) {
      pooledE += expected[i];
      pooledO += observed[i];
      continue;
    }
    double d = observed[i] - expected[i];
    r.statistic += d * d / expected[i];
    ++r.dof;
  }
  if (pooledE > 5.0) {
    double d = pooledO - pooledE;
    r.statistic += d * d / pooledE;
    ++r.dof;
  }
  r.dof = std::max(r.dof - 1, 1);
  double k = r.dof, z = (std::cbrt(r.statistic / k) - (1.0 - 2.0 / (9.0 * k))) /
                       std::sqrt(2.0 / (9.0 * k));
  r.pValue = 0.5 * std::erfc(z / std::sqrt(2.0));
  return r;
}

std::vector<probe::ProbeCase> layeredCases() {
  glm::vec3 base(0.8f, 0.5f, 0.2f);
  std::vector<probe::ProbeCase> cases;
  for (float theta : {0.f, 45.f, 75.f}) {
    cases.push_back(coat(makeCase(base, 0.f, 0.6f, theta), 1.f, 0.3f));
    cases.push_back(coat(makeCase(base, 1.f, 0.4f, theta), 0.7f, 0.5f, {0.2f, 0.1f, 1.f}));
    cases.push_back(sheen(makeCase(base, 0.f, 0.8f, theta), {0.9f, 0.6f, 0.7f}, 0.5f));
    cases.push_back(sheen(makeCase(glm::vec3(0.f), 0.f, 0.8f, theta, 0.f, 1.5f, glm::vec3(0.f)),
                          {1.f, 1.f, 1.f}, 0.9f));
    cases.push_back(diffuseTransmission(makeCase(base, 0.f, 0.5f, theta), 0.6f, {0.3f, 0.9f, 0.5f}));
    cases.push_back(anisotropy(makeCase(base, 1.f, 0.4f, theta), 0.8f, 0.7f));
    cases.push_back(anisotropy(makeCase(base, 0.f, 0.5f, theta), 0.5f, 2.1f));
    // Thin films over a metal, a dielectric, and rough glass entered from outside and inside.
    cases.push_back(film(makeCase(base, 1.f, 0.3f, theta), 1.f, 1.8f, 380.f));
    cases.push_back(film(makeCase(base, 0.f, 0.5f, theta), 0.7f, 1.3f, 550.f));
    for (float eta : {1.5f, 1.f / 1.5f})
      cases.push_back(film(makeCase(glm::vec3(1.f), 0.f, 0.5f, theta, 1.f, eta), 1.f, 2.0f, 300.f));
  }
  // Everything at once, over rough glass.
  probe::ProbeCase all = makeCase(base, 0.2f, 0.5f, 35.f, 0.3f, 1.5f);
  all = anisotropy(diffuseTransmission(sheen(coat(all, 0.8f, 0.4f, {0.1f, -0.2f, 1.f}),
                                             {0.5f, 0.5f, 0.9f}, 0.4f),
                                       0.5f, {1.f, 0.8f, 0.6f}),
                   0.6f, 1.0f);
  cases.push_back(film(all, 0.9f, 1.5f, 420.f));
  return cases;
}

}  // namespace

TEST(BsdfProbe, LayeredLobesSamplingMatchesEvaluation) {
  pt::BsdfProbe p(test::context());
  std::vector<probe::ProbeCase> cases = layeredCases();
  const double kSignificance = 0.01 / double(cases.size());  // Sidak-like correction
  for (size_t first = 0; first < cases.size(); first += 8) {
    std::vector<probe::ProbeCase> batch(cases.begin() + first,
                                        cases.begin() + std::min(cases.size(), first + 8));
    auto q = integrate(p, batch);
    auto s = sample(p, batch);
    auto evalOut = p.run(batch, probe::ProbePush{probe::kProbeEval, 0, kTheta, kPhi, 0, 0});
    auto sampleOut = p.run(batch, probe::ProbePush{probe::kProbeSample, 0, 0, 0, kSamples, 7});
    for (size_t c = 0; c < batch.size(); ++c) {
      SCOPED_TRACE(describe(batch[c]));
      EXPECT_TRUE(s[c].finite);
      for (int k = 0; k < 3; ++k) {
        double tol = 5.0 * s[c].stderr_[k] + 0.005 * q[c].albedo[k] + 1e-4;
        EXPECT_NEAR(s[c].mean[k], q[c].albedo[k], tol) << "channel " << k;
        // The sheen lobe alone exceeds 1 only at grazing angles (lib/sheen_albedo.glsl).
        EXPECT_LE(q[c].albedo[k], 1.0 + 0.01) << "channel " << k << ": gains energy";
      }
      EXPECT_NEAR(q[c].pdfMass, s[c].validFraction, 0.01 + 0.005);
      ChiSquare chi = chiSquare(evalOut, sampleOut, c);
      EXPECT_GT(chi.pValue, kSignificance)
          << "chi-square " << chi.statistic << " with " << chi.dof << " degrees of freedom";
    }
  }
}

// White furnaces: a lobe that only redistributes light keeps the albedo at 1 (diffuse
// transmission of a white, specular-free surface; a white diffuse base under a smooth coat,
// up to the coat's single-scattering loss) and none exceeds it.
TEST(BsdfProbe, LayeredLobesWhiteFurnace) {
  pt::BsdfProbe p(test::context());
  glm::vec3 white(1.f), none(0.f);
  std::vector<probe::ProbeCase> conserving, bounded;
  for (float theta : {0.f, 40.f, 70.f}) {
    for (float dt : {0.3f, 1.f})
      conserving.push_back(diffuseTransmission(makeCase(white, 0.f, 1.f, theta, 0.f, 1.5f, none), dt, white));
    conserving.push_back(coat(makeCase(white, 0.f, 1.f, theta, 0.f, 1.5f, none), 1.f, 0.05f));
    bounded.push_back(coat(makeCase(white, 0.f, 0.3f, theta), 1.f, 0.6f));
    bounded.push_back(sheen(makeCase(white, 0.f, 0.5f, theta), white, 0.3f));
    bounded.push_back(sheen(makeCase(white, 0.f, 1.f, theta, 0.f, 1.5f, none), white, 1.f));
    bounded.push_back(anisotropy(makeCase(white, 1.f, 0.3f, theta), 1.f, 0.3f));
    bounded.push_back(anisotropy(makeCase(white, 0.f, 0.2f, theta, 1.f, 1.5f), 0.7f, 1.3f));
    bounded.push_back(film(makeCase(white, 1.f, 0.3f, theta), 1.f, 1.8f, 400.f));
    bounded.push_back(film(makeCase(white, 0.f, 0.5f, theta), 1.f, 2.2f, 250.f));
    bounded.push_back(film(makeCase(white, 0.f, 0.5f, theta, 1.f, 1.5f), 1.f, 1.4f, 600.f));
  }
  // A film over white glass only splits light between reflection and refraction: each
  // channel's R + T is 1 (smooth glass, whose samples are delta).
  for (float theta : {0.f, 40.f, 70.f})
    for (float nm : {150.f, 500.f})
      conserving.push_back(film(makeCase(white, 0.f, 0.f, theta, 1.f, 1.5f), 1.f, 1.8f, nm));
  // Sampled (the smooth coat's peak is narrower than the quadrature grid's cells).
  auto sc = sample(p, conserving);
  for (size_t c = 0; c < conserving.size(); ++c) {
    SCOPED_TRACE(describe(conserving[c]));
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(sc[c].mean[k], 1.0, 0.015 + 5.0 * sc[c].stderr_[k]) << "channel " << k;
  }
  for (size_t first = 0; first < bounded.size(); first += 8) {
    std::vector<probe::ProbeCase> batch(bounded.begin() + first,
                                        bounded.begin() + std::min(bounded.size(), first + 8));
    auto q = integrate(p, batch);
    for (size_t c = 0; c < batch.size(); ++c) {
      SCOPED_TRACE(describe(batch[c]));
      for (int k = 0; k < 3; ++k) {
        EXPECT_LE(q[c].albedo[k], 1.0 + 0.01) << "channel " << k;
        EXPECT_GT(q[c].albedo[k], 0.5) << "channel " << k << ": lost most of the light";
      }
    }
  }
}

// Anisotropy turns with its direction: rotating both the direction and wo about the normal
// leaves the albedo unchanged; strength 0 is the isotropic lobe exactly.
TEST(BsdfProbe, AnisotropyFollowsItsDirection) {
  pt::BsdfProbe p(test::context());
  glm::vec3 base(0.9f, 0.7f, 0.4f);
  probe::ProbeCase a = anisotropy(makeCase(base, 1.f, 0.3f, 60.f), 0.9f, 0.f);
  probe::ProbeCase b = anisotropy(makeCase(base, 1.f, 0.3f, 60.f), 0.9f, 1.f);
  b.wo = glm::vec4(std::cos(1.f) * a.wo.x, std::sin(1.f) * a.wo.x, a.wo.z, 0.f);
  probe::ProbeCase across = anisotropy(makeCase(base, 1.f, 0.3f, 60.f), 0.9f, float(kPi / 2));
  probe::ProbeCase iso = anisotropy(makeCase(base, 1.f, 0.3f, 60.f), 0.f, 0.4f);
  probe::ProbeCase plain = makeCase(base, 1.f, 0.3f, 60.f);
  auto q = integrate(p, {a, b, across, iso, plain});
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(q[0].albedo[k], q[1].albedo[k], 2e-3);
    EXPECT_NEAR(q[3].albedo[k], q[4].albedo[k], 1e-6);
    // Turning the direction a quarter turn changes what the lobe reflects.
    EXPECT_GT(std::abs(q[0].albedo[k] - q[2].albedo[k]), 0.01);
  }
}

// The shared thin-film Fresnel on the host: in [0, 1] per channel over the extension's whole
// range (the series it specifies is not, so it is clamped), 1 at grazing incidence, and
// coloured where a film of about half a wavelength interferes.
TEST(ThinFilm, FresnelIsAReflectanceWithTheRightLimits) {
  namespace tf = osr::gpu::thin_film;
  for (float ior : {1.0f, 1.3f, 1.8f, 2.5f})
    for (float nm : {1.f, 100.f, 250.f, 400.f, 800.f, 1200.f})
      for (float f0 : {0.f, 0.04f, 0.3f, 0.9f, 1.f})
        for (int i = 0; i <= 20; ++i) {
          float c = i / 20.f;
          glm::vec3 f = tf::thinFilmFresnel(1.f, ior, nm, glm::vec3(f0), c);
          for (int k = 0; k < 3; ++k) {
            ASSERT_TRUE(f[k] >= 0.f && f[k] <= 1.f)
                << "ior " << ior << " " << nm << " nm F0 " << f0 << " cos " << c << " channel " << k
                << ": " << f[k];
          }
          if (c == 0.f) {
            EXPECT_NEAR(f.x, 1.f, 1e-3f);
          }
        }
  // It is coloured: at 380 nm, ior 1.8, normal incidence, the channels differ.
  glm::vec3 f = tf::thinFilmFresnel(1.f, 1.8f, 380.f, glm::vec3(0.04f), 1.f);
  EXPECT_GT(std::max({f.x, f.y, f.z}) - std::min({f.x, f.y, f.z}), 0.05f);
}

// The film colours what a grey metal reflects, and a factor of 0 is no film at all.
TEST(BsdfProbe, IridescenceColoursTheSpecularLayer) {
  pt::BsdfProbe p(test::context());
  probe::ProbeCase plain = makeCase(glm::vec3(0.5f), 1.f, 0.3f, 45.f);
  auto q = integrate(p, {plain, film(plain, 1.f, 1.8f, 380.f), film(plain, 0.f, 1.8f, 380.f)});
  double lo = std::min({q[1].albedo.x, q[1].albedo.y, q[1].albedo.z});
  double hi = std::max({q[1].albedo.x, q[1].albedo.y, q[1].albedo.z});
  EXPECT_GT(hi - lo, 0.05) << q[1].albedo.x << " " << q[1].albedo.y << " " << q[1].albedo.z;
  for (int k = 0; k < 3; ++k) EXPECT_EQ(q[2].albedo[k], q[0].albedo[k]);
}
