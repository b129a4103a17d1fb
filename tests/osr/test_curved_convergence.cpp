// OSR's two levels integrate the same function on curved surfaces: the composite's closed
// form for the diffuse lobe and the residual's control variate (osr_residual, lib/osr_maps.glsl
// gatherShRadiance), so composite + the whole residual converges to the path tracer's answer
// where pixel and map normals differ (docs/osr.md "Converging: the residual"). Scenes:
// diffuse spheres, a cylinder and a torus in a room lit by a lamp and a window; a sphere in
// a uniform environment; the inside of an emissive sphere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "osr/osr_test_util.h"
#include "pt/path_integrator.h"

using namespace osr;

namespace {

// Diffuse spheres, a cylinder and a torus on the floor of a room open towards the camera,
// under a point lamp and beside an emissive window; every surface Lambertian (albedo 0.75),
// so most of the light on the objects' shadowed sides is indirect.
std::string writeCurvedRoom(const std::string& tag) {
  test::GltfWriter g;
  int white = g.material(test::GltfWriter::diffuse(glm::vec3(0.75f)));
  int warm = g.material(test::GltfWriter::diffuse(glm::vec3(0.8f, 0.6f, 0.4f)));
  int window = g.material(test::GltfWriter::emitter(glm::vec3(4.f, 4.f, 3.5f), false));
  g.quad({-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, white);     // floor
  g.quad({-2, 0, -2}, {2, 0, -2}, {2, 2.5f, -2}, {-2, 2.5f, -2}, white);  // back wall
  g.quad({-2, 0, 2}, {-2, 0, -2}, {-2, 2.5f, -2}, {-2, 2.5f, 2}, warm);   // left wall
  g.quad({-2, 2.5f, -2}, {2, 2.5f, -2}, {2, 2.5f, 2}, {-2, 2.5f, 2}, white);  // ceiling
  g.quad({1.99f, 0.6f, -1.2f}, {1.99f, 0.6f, 0.2f}, {1.99f, 1.8f, 0.2f}, {1.99f, 1.8f, -1.2f},
         window);  // facing -x
  g.sphere({-0.9f, 0.55f, -0.3f}, 0.55f, white);
  g.sphere({0.2f, 0.3f, 0.8f}, 0.3f, warm);
  g.cylinder({0.8f, 0.f, -0.9f}, 0.35f, 1.0f, white);
  g.torus({0.9f, 0.18f, 0.5f}, 0.45f, 0.18f, white);
  g.light({{"type", "point"}, {"intensity", 683.0 * 4.0}, {"_translation", {-0.3, 2.2, 0.6}}});
  g.camera({0.1f, 1.7f, 4.3f}, {0.f, 0.55f, 0.f}, 0.75f);
  std::string path = (test::tempDir(tag) / "curved_room.gltf").string();
  g.write(path);
  return path;
}

using test::pathTrace;

double luminance(const std::vector<float>& layer, size_t p) {
  return 0.2126 * layer[p * 3] + 0.7152 * layer[p * 3 + 1] + 0.0722 * layer[p * 3 + 2];
}

// How far two renders' layers are apart in units of their noise: per b x b block, the mean
// luminance difference over its standard error (from the spread of the block's pixel
// differences); returns the mean of the squared z scores over the blocks (about 1 when the
// two estimate the same image, larger where one is biased) and the largest |z|.
struct BlockZ {
  double meanSq = 0, maxAbs = 0;
};
BlockZ blockZ(const std::vector<float>& a, const std::vector<float>& b, int size, int bs) {
  BlockZ out;
  int blocks = 0;
  for (int by = 0; by < size / bs; ++by)
    for (int bx = 0; bx < size / bs; ++bx) {
      double s = 0, s2 = 0;
      const int n = bs * bs;
      for (int y = 0; y < bs; ++y)
        for (int x = 0; x < bs; ++x) {
          const size_t p = size_t(by * bs + y) * size + bx * bs + x;
          const double d = luminance(a, p) - luminance(b, p);
          s += d;
          s2 += d * d;
        }
      const double mean = s / n, var = std::max(0.0, s2 / n - mean * mean) / (n - 1);
      if (var <= 0) continue;
      const double z = mean / std::sqrt(var);
      out.meanSq += z * z;
      out.maxAbs = std::max(out.maxAbs, std::abs(z));
      ++blocks;
    }
  out.meanSq /= std::max(blocks, 1);
  return out;
}

// The mean luminance difference of two layers over the image in units of its standard error
// (from the spread of the pixel differences; pixels' errors are independent): about N(0, 1)
// when both estimate the same image, |z| grows as the square root of the samples with a bias.
double globalZ(const std::vector<float>& a, const std::vector<float>& b) {
  const size_t n = a.size() / 3;
  double s = 0, s2 = 0;
  for (size_t p = 0; p < n; ++p) {
    const double d = luminance(a, p) - luminance(b, p);
    s += d;
    s2 += d * d;
  }
  const double mean = s / n, var = std::max(0.0, s2 / n - mean * mean) / (n - 1);
  return var > 0 ? mean / std::sqrt(var) : 0.0;
}

double relMse(const std::vector<float>& a, const std::vector<float>& ref) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = a[i] - ref[i];
    sum += d * d / (ref[i] * ref[i] + 1e-2);
  }
  return sum / double(a.size());
}

}  // namespace

TEST(CurvedConvergence, CompositePlusResidualIsThePathTracer) {
  // The whole residual from the first pass (ramp 0: beta = 1), so the estimate is unbiased at
  // any pass count: its indirect layer must match the path tracer's within their noise. A
  // coarse grid (r = 16 on 48 x 48) gives pixels whose normals differ much from their maps'.
  auto s = test::loadForTest(writeCurvedRoom("curved_convergence"));
  const uint32_t size = 48, passes = 48;
  auto p = pathTrace(s, size, 1024);
  // With the residual's first directions drawn from the BSDF alone, then 80 % of them from
  // the maps on these diffuse surfaces (--residual-guide: one-sample MIS, still unbiased).
  for (float guide : {0.f, 0.8f}) {
    oneshot::OsrSettings set;
    set.residualRamp = 0.0;
    set.residualGuide = guide;
    oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
    auto o = test::renderOsrPasses(osr, s, passes);
    const BlockZ z = blockZ(o.indirect, p.indirect, int(size), 6);
    std::printf("curved room, %u passes, guide %.1f: indirect block z^2 mean %.2f, max |z| %.2f; "
                "relMSE %.5f\n",
                passes, guide, z.meanSq, z.maxAbs, relMse(o.indirect, p.indirect));
    // Unbiased on both sides: z^2 averages about 1 over the 64 blocks (1.3 measured: the heavy
    // tails of a few hundred paths per pixel near the lamp). The maps' SH truncation the old
    // control variate left in was 1-4% of a block's indirect light here, below this noise:
    // InsideAHalfEmissiveSphere is the test that sees it.
    EXPECT_LT(z.meanSq, 2.0) << "guide " << guide;
  }
}

TEST(CurvedConvergence, SphereInAUniformEnvironment) {
  // A convex sphere never sees itself: the light leaving it has bounced once, a Le (albedo
  // a, environment Le), all of it direct light; the indirect layer is exactly 0 (no path has
  // a second surface), whatever the maps and the residual.
  const float a = 0.6f, le = 0.5f;
  test::GltfWriter g;
  g.sphere({0, 0, 0}, 1.f, g.material(test::GltfWriter::diffuse(glm::vec3(a))));
  g.camera({0.f, 0.3f, 3.2f}, {0.f, 0.f, 0.f}, 0.8f);
  const std::string path = (test::tempDir("curved_furnace") / "sphere.gltf").string();
  g.write(path);
  auto& ctx = test::context();
  test::LoadedScene s;
  s.scene = scene::loadScene(path);
  s.camera = scene::selectCamera(s.scene, "", 1.f);
  scene::Environment env;
  env.width = 8;
  env.height = 4;
  env.texels.assign(32, glm::vec4(le, le, le, 1.f));
  s.gpu = std::make_unique<scene::GpuScene>(ctx, s.scene, &env);
  s.bvh = bvh::buildGpu(ctx, s.gpu->vertices, s.gpu->triangles, s.gpu->triangleCount);
  oneshot::OsrSettings set;
  set.gridStart = set.gridMin = 4;
  set.residualRamp = 0.0;
  const uint32_t size = 24;
  oneshot::OsrIntegrator osr(ctx, *s.gpu, s.bvh, size, size, set);
  auto o = test::renderOsrPasses(osr, s, 8);
  // Pixels whose first hits, and their neighbours' (the pixel filter reaches 1 px past a
  // pixel), were all on the sphere or all missed it.
  auto all = [&](int x, int y, float albedo) {
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) {
        const int u = std::clamp(x + dx, 0, int(size) - 1), v = std::clamp(y + dy, 0, int(size) - 1);
        if (std::abs(o.albedo[(size_t(v) * size + u) * 3] - albedo) > 1e-4f) return false;
      }
    return true;
  };
  double sphere = 0, background = 0;
  int nSphere = 0, nBackground = 0;
  for (int y = 0; y < int(size); ++y)
    for (int x = 0; x < int(size); ++x) {
      const size_t i = size_t(y) * size + x;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(o.indirect[i * 3 + c], 0.f) << "pixel " << i;
      if (all(x, y, a)) sphere += o.combined[i * 3], ++nSphere;
      if (all(x, y, 0.f)) background += o.combined[i * 3], ++nBackground;
    }
  ASSERT_GT(nSphere, 60);
  ASSERT_GT(nBackground, 30);
  std::printf("sphere in furnace: sphere %.4f (analytic %.4f), background %.4f\n",
              sphere / nSphere, a * le, background / nBackground);
  // 8 passes x 16 light samples x ~200 pixels: well within 1%.
  EXPECT_NEAR(sphere / nSphere, a * le, 0.01 * a * le);
  EXPECT_NEAR(background / nBackground, le, 1e-4 * le);
}

TEST(CurvedConvergence, InsideAnEmissiveSphere) {
  // A closed sphere whose inside emits Le = 1 with albedo a = 0.5, seen from inside: radiance
  // Le / (1 - a) = 2 everywhere, of which the direct layer (emission seen + one bounce) holds
  // Le (1 + a) = 1.5 and the indirect a^2 Le / (1 - a) = 0.5. Every pixel's normal differs
  // from its maps' (a 4-pixel grid on a curved wall), the residual shown in full.
  test::GltfWriter g;
  auto m = test::GltfWriter::diffuse(glm::vec3(0.5f));
  m["emissiveFactor"] = {1.0, 1.0, 1.0};
  g.sphere({0, 0, 0}, 1.f, g.material(m), 24, 48, /*inward=*/true);
  g.camera({0.1f, -0.2f, 0.4f}, {0.4f, -0.5f, -1.f}, 1.2f);
  const std::string path = (test::tempDir("curved_emissive") / "inside.gltf").string();
  g.write(path);
  auto s = test::loadForTest(path);
  oneshot::OsrSettings set;
  set.gridStart = set.gridMin = 4;
  set.residualRamp = 0.0;
  const uint32_t size = 16;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
  auto o = test::renderOsrPasses(osr, s, 16);
  double indirect = 0, direct = 0;
  for (size_t i = 0; i < o.indirect.size(); ++i) indirect += o.indirect[i], direct += o.direct[i];
  const double n = double(o.indirect.size());
  std::printf("inside an emissive sphere: indirect %.4f (0.5), direct %.4f (1.5)\n",
              indirect / n, direct / n);
  EXPECT_NEAR(indirect / n, 0.5, 0.01);
  EXPECT_NEAR(direct / n, 1.5, 0.02);
}

TEST(CurvedConvergence, InsideAHalfEmissiveSphere) {
  // The inside of a sphere whose upper half emits: the light after one bounce has a sharp
  // edge at the equator, which the maps' order-2 SH does not hold, and every pixel's normal
  // differs from its maps'. The whole residual from the first pass (ramp 0): the image's mean
  // indirect light must be the path tracer's within 3 standard errors. With the texel
  // lookups as control variate (the composite's SH irradiance integrating another function)
  // it was 0.4% low, 3.4 standard errors at 64 passes (docs/osr.md).
  test::GltfWriter g;
  auto glow = test::GltfWriter::diffuse(glm::vec3(0.5f));
  glow["emissiveFactor"] = {1.0, 1.0, 1.0};
  const int top = g.material(glow), bottom = g.material(test::GltfWriter::diffuse(glm::vec3(0.7f)));
  std::vector<glm::vec2> upper, lower;
  const int rings = 16;
  for (int i = rings; i >= 0; --i) {  // inward: from the equator up, and from the pole up
    const float th = 0.5f * float(M_PI) * i / rings;
    upper.push_back({i == 0 ? 0.f : std::sin(th), std::cos(th)});
    const float tl = 0.5f * float(M_PI) * (1.f + float(i) / rings);
    lower.push_back({i == rings ? 0.f : std::sin(tl), std::cos(tl)});
  }
  g.revolve({0, 0, 0}, upper, top);
  g.revolve({0, 0, 0}, lower, bottom);
  g.camera({0.f, 0.1f, 0.6f}, {0.f, -0.1f, -1.f}, 1.4f);
  const std::string path = (test::tempDir("curved_half") / "half.gltf").string();
  g.write(path);
  auto s = test::loadForTest(path);
  oneshot::OsrSettings set;
  set.gridStart = set.gridMin = 8;
  set.residualRamp = 0.0;
  set.directSamples = set.directSamplesLate = 1;  // the indirect layer is compared
  set.cameraSamples = set.cameraSamplesLate = 1;
  const uint32_t size = 32;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
  auto o = test::renderOsrPasses(osr, s, 128);
  auto p = pathTrace(s, size, 2048);
  const double z = globalZ(o.indirect, p.indirect);
  std::printf("half-emissive sphere: indirect mean z %.2f; relMSE %.5f\n", z,
              relMse(o.indirect, p.indirect));
  EXPECT_LT(std::abs(z), 3.0);
}

// Every layered lobe at once (clearcoat, sheen, anisotropy with an iridescent film, diffuse
// transmission, absorbing glass): the composite takes only the diffuse and base glossy lobes from the maps, the
// residual path-traces the rest (docs/osr.md), so OSR still converges to the path tracer. The
// paper screen between the window and the objects glows only through the residual's paths.
TEST(CurvedConvergence, LayeredLobesConvergeToThePathTracer) {
  test::GltfWriter g;
  using json = nlohmann::json;
  auto with = [](json m, const char* ext, json value) {
    m["extensions"][ext] = value;
    return m;
  };
  json red = test::GltfWriter::diffuse(glm::vec3(0.7f, 0.2f, 0.1f));
  red["extensions"].erase("KHR_materials_specular");
  int white = g.material(test::GltfWriter::diffuse(glm::vec3(0.75f)));
  int window = g.material(test::GltfWriter::emitter(glm::vec3(4.f, 4.f, 3.5f), false));
  int coated = g.material(with(red, "KHR_materials_clearcoat",
                               {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", 0.2}}));
  int velvet = g.material(with(red, "KHR_materials_sheen",
                               {{"sheenColorFactor", {0.9, 0.8, 0.9}}, {"sheenRoughnessFactor", 0.5}}));
  json paper = with(test::GltfWriter::diffuse(glm::vec3(0.9f, 0.85f, 0.7f)),
                    "KHR_materials_diffuse_transmission",
                    {{"diffuseTransmissionFactor", 0.7}, {"diffuseTransmissionColorFactor", {1.0, 0.7, 0.4}}});
  paper["doubleSided"] = true;
  int screen = g.material(paper);
  json glass = with(test::GltfWriter::glass(1.5f), "KHR_materials_volume",
                    {{"thicknessFactor", 1.0}, {"attenuationColor", {0.3, 0.6, 0.9}},
                     {"attenuationDistance", 0.5}});
  glass["pbrMetallicRoughness"]["roughnessFactor"] = 0.3;
  int tinted = g.material(glass);
  json metal = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.9, 0.8, 0.6, 1.0}},
                                          {"metallicFactor", 1.0}, {"roughnessFactor", 0.4}}},
                {"extensions", {{"KHR_materials_anisotropy", {{"anisotropyStrength", 0.8}}},
                                {"KHR_materials_iridescence", {{"iridescenceFactor", 1.0},
                                                               {"iridescenceIor", 1.8},
                                                               {"iridescenceThicknessMaximum", 380.0}}}}}};
  int brushed = g.material(metal);
  g.quad({-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, white);
  g.quad({-2, 0, -2}, {2, 0, -2}, {2, 2.5f, -2}, {-2, 2.5f, -2}, white);
  g.quad({-2, 2.5f, -2}, {2, 2.5f, -2}, {2, 2.5f, 2}, {-2, 2.5f, 2}, white);
  g.quad({1.99f, 0.6f, -1.2f}, {1.99f, 0.6f, 0.2f}, {1.99f, 1.8f, 0.2f}, {1.99f, 1.8f, -1.2f},
         window);
  g.quad({1.4f, 0.2f, -1.4f}, {1.4f, 0.2f, 0.4f}, {1.4f, 2.0f, 0.4f}, {1.4f, 2.0f, -1.4f}, screen);
  g.sphere({-0.9f, 0.55f, -0.3f}, 0.55f, coated);
  g.sphere({0.2f, 0.3f, 0.8f}, 0.3f, velvet);
  g.sphere({0.6f, 0.35f, -0.6f}, 0.35f, tinted);
  g.cylinder({-0.2f, 0.f, -1.2f}, 0.3f, 0.9f, brushed);
  g.light({{"type", "point"}, {"intensity", 683.0 * 4.0}, {"_translation", {-0.3, 2.2, 0.6}}});
  g.camera({0.1f, 1.7f, 4.3f}, {0.f, 0.55f, 0.f}, 0.75f);
  std::string path = (test::tempDir("layered_convergence") / "layered.gltf").string();
  g.write(path);
  auto s = test::loadForTest(path);
  EXPECT_TRUE(s.scene.warnings.empty()) << s.scene.warnings.front();
  const uint32_t size = 48, passes = 48;
  oneshot::OsrSettings set;
  set.residualRamp = 0.0;
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
  auto o = test::renderOsrPasses(osr, s, passes);
  auto p = pathTrace(s, size, 1024);
  const BlockZ z = blockZ(o.indirect, p.indirect, int(size), 6);
  std::printf("layered room, %u passes: indirect block z^2 mean %.2f, max |z| %.2f; relMSE %.5f\n",
              passes, z.meanSq, z.maxAbs, relMse(o.indirect, p.indirect));
  EXPECT_LT(z.meanSq, 2.0);
  EXPECT_LT(std::abs(globalZ(o.indirect, p.indirect)), 4.0);
}

// A rough metal sphere's rim reflects directions that graze its surface, which lie below the
// hemispheres of the maps around it (their normals face the camera more). The composite
// counts such directions 0 and the residual traces them in full, unblended; before, they
// were looked up as black and only the blended residual could bring them back, so with the
// residual barely blended in (early passes, noisy pixels) the rim came out dark: 27 % on
// scenes/room's sphere at 10 passes (docs/osr.md "Integration against the BSDF").
TEST(CurvedConvergence, GlossySphereRimWithoutTheResidualBlend) {
  test::GltfWriter g;
  int white = g.material(test::GltfWriter::diffuse(glm::vec3(0.75f)));
  int warm = g.material(test::GltfWriter::diffuse(glm::vec3(0.8f, 0.5f, 0.4f)));
  int window = g.material(test::GltfWriter::emitter(glm::vec3(4.f, 4.f, 3.5f), false));
  const glm::vec3 metalColour(0.9f, 0.7f, 0.5f);
  int metal = g.material({{"pbrMetallicRoughness",
                           {{"baseColorFactor", {metalColour.x, metalColour.y, metalColour.z, 1.0}},
                            {"metallicFactor", 1.0}, {"roughnessFactor", 0.25}}}});
  g.quad({-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, warm);
  g.quad({-2, 0, -2}, {2, 0, -2}, {2, 2.5f, -2}, {-2, 2.5f, -2}, white);
  g.quad({-2, 0, 2}, {-2, 0, -2}, {-2, 2.5f, -2}, {-2, 2.5f, 2}, warm);
  g.quad({-2, 2.5f, -2}, {2, 2.5f, -2}, {2, 2.5f, 2}, {-2, 2.5f, 2}, white);
  g.quad({1.99f, 0.6f, -1.2f}, {1.99f, 0.6f, 0.2f}, {1.99f, 1.8f, 0.2f}, {1.99f, 1.8f, -1.2f},
         window);
  g.sphere({0.f, 0.7f, 0.f}, 0.7f, metal);
  g.light({{"type", "point"}, {"intensity", 683.0 * 4.0}, {"_translation", {-0.3, 2.2, 0.6}}});
  g.camera({0.1f, 1.2f, 3.8f}, {0.f, 0.7f, 0.f}, 0.75f);
  const std::string path = (test::tempDir("glossy_rim") / "glossy_rim.gltf").string();
  g.write(path);
  auto s = test::loadForTest(path);
  const uint32_t size = 64;
  oneshot::OsrSettings set;
  set.residualRamp = 1e9;  // beta = k / (k + 1e9): the blended residual left out
  oneshot::OsrIntegrator osr(test::context(), *s.gpu, s.bvh, size, size, set);
  auto o = test::renderOsrPasses(osr, s, 16);
  auto p = pathTrace(s, size, 512);
  // The sphere's pixels by their albedo; the rim: those within 2 pixels of another surface.
  // The metal's albedo guide is its directional albedo, metalColour A + B with A and B that
  // change with the view (lib/bsdf.glsl denoiseAlbedo), so its steps R - G and G - B stay
  // equal (0.2 A); the warm walls' differ (0.3, 0.1), the white ones' are 0. A pixel shared
  // with a wall or the window keeps equal steps, but its mean normal is short.
  auto onSphere = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= int(size) || y >= int(size)) return false;
    const size_t i = (size_t(y) * size + x) * 3;
    const float rg = o.albedo[i] - o.albedo[i + 1], gb = o.albedo[i + 1] - o.albedo[i + 2];
    const glm::vec3 n(o.normal[i], o.normal[i + 1], o.normal[i + 2]);
    return rg > 0.05f && std::abs(rg - gb) < 0.01f && glm::length(n) > 0.95f;
  };
  double osrRim = 0, pathRim = 0, osrInner = 0, pathInner = 0;
  int rim = 0, inner = 0;
  for (int y = 0; y < int(size); ++y)
    for (int x = 0; x < int(size); ++x) {
      if (!onSphere(x, y)) continue;
      bool edge = false;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) edge = edge || !onSphere(x + dx, y + dy);
      const size_t i = size_t(y) * size + x;
      (edge ? osrRim : osrInner) += luminance(o.indirect, i);
      (edge ? pathRim : pathInner) += luminance(p.indirect, i);
      ++(edge ? rim : inner);
    }
  ASSERT_GT(rim, 40);
  ASSERT_GT(inner, 40);
  std::printf("glossy sphere, residual left out: rim indirect %.4f (path %.4f, %.3fx), "
              "inner %.4f (path %.4f, %.3fx), %d + %d pixels\n",
              osrRim / rim, pathRim / rim, osrRim / pathRim, osrInner / inner, pathInner / inner,
              osrInner / pathInner, rim, inner);
  EXPECT_GT(osrRim / pathRim, 0.9);
  EXPECT_LT(osrRim / pathRim, 1.1);
}
