// The path tracer on scenes with known answers: white furnaces (diffuse albedo 1 and a smooth
// dielectric inside a uniform environment give the environment's radiance), a diffuse plane
// under a square emitter, point, spot and directional lights (analytic irradiance), a fixed
// seed reproduces the image bit for bit, combined = direct + indirect, and the pixel filter is
// Cycles' Blackman-Harris (an emitter's edge).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "image/image_io.h"
#include "bvh/bvh.h"
#include "common/pixel_filter_cdf.h"
#include "common/vk_test.h"
#include "pt/gltf_writer.h"
#include "pt/path_integrator.h"
#include "scene_gpu/gpu_scene.h"
#include "scene/scene.h"
#include "shaders/shared/pt.h"

using namespace osr;
namespace fs = std::filesystem;
using test::GltfWriter;

namespace {

fs::path tempDir() { return test::tempDir("renderer"); }

struct Rendered {
  render::FilmLayers film;
  scene::Scene scene;
  scene::Camera camera;
};

Rendered renderFile(const std::string& gltf, uint32_t size, uint32_t spp, uint32_t seed = 1,
                    const scene::Environment* env = nullptr,
                    pt::Mode mode = pt::Mode::Path, double batchTargetS = 0.25,
                    render::RenderStats* stats = nullptr) {
  auto& ctx = test::context();
  Rendered r;
  r.scene = scene::loadScene(gltf);
  r.camera = scene::selectCamera(r.scene, "", 1.f);
  scene::GpuScene gs(ctx, r.scene, env);
  bvh::Bvh tree = bvh::buildGpu(ctx, gs.vertices, gs.triangles, gs.triangleCount);
  pt::RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.seed = seed;
  s.mode = mode;
  s.batchTargetS = batchTargetS;
  // The analytic expectations below average over each pixel's square.
  s.pixelFilter = gpu::camera::kPixelFilterBox;
  r.film = pt::render(ctx, gs, tree, r.camera, s, {}, stats);
  return r;
}

scene::Environment uniformEnvironment(float radiance) {
  scene::Environment env;
  env.width = 8;
  env.height = 4;
  env.texels.assign(32, glm::vec4(radiance, radiance, radiance, 1.f));
  return env;
}

// The camera ray through image point (px, py) in pixels, as pt_trace.comp builds it.
void cameraRay(const scene::Camera& c, uint32_t size, float px, float py, glm::vec3& o,
               glm::vec3& d) {
  float t = std::tan(0.5f * c.yfov);
  glm::vec3 local((px / size * 2 - 1) * t, (1 - py / size * 2) * t, -1.f);
  o = glm::vec3(c.worldFromCamera[3]);
  d = glm::normalize(glm::mat3(c.worldFromCamera) * local);
}

// Expected value of a pixel that sees the ground plane y = 0 (|x|, |z| < 3.9): the n x n
// sub-pixel average of value(q, o, dir) at the ground points q. Returns a negative number when
// a sub-ray misses the ground or value() flags it (returns < 0).
template <class F>
double groundPixel(const scene::Camera& c, uint32_t size, uint32_t px, uint32_t py, F value,
                   int n = 4) {
  double sum = 0;
  for (int sy = 0; sy < n; ++sy)
    for (int sx = 0; sx < n; ++sx) {
      glm::vec3 o, dir;
      cameraRay(c, size, px + (sx + 0.5f) / n, py + (sy + 0.5f) / n, o, dir);
      float t = -o.y / dir.y;
      glm::vec3 q = o + t * dir;
      if (!(t > 0) || std::abs(q.x) > 3.9f || std::abs(q.z) > 3.9f) return -1;
      double v = value(q, o, dir);
      if (v < 0) return -1;
      sum += v / (n * n);
    }
  return sum;
}

// Irradiance at p (normal n) from a uniformly emitting polygon of radiance 1 (Lambert's
// formula: E = 1/2 sum over edges of the angle subtended times the cosine to n).
double polygonIrradiance(glm::dvec3 p, glm::dvec3 n, const std::vector<glm::dvec3>& poly) {
  double e = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) {
    glm::dvec3 a = glm::normalize(poly[i] - p), b = glm::normalize(poly[(i + 1) % poly.size()] - p);
    glm::dvec3 c = glm::cross(a, b);
    double len = glm::length(c);
    if (len > 0) e += std::acos(glm::clamp(glm::dot(a, b), -1.0, 1.0)) * glm::dot(c / len, n);
  }
  return 0.5 * std::abs(e);
}

double mean(const std::vector<float>& v) {
  double s = 0;
  for (float x : v) s += x;
  return s / double(v.size());
}

}  // namespace

TEST(PathIntegrator, WhiteFurnaceDiffuseAndSmoothDielectric) {
  fs::path d = tempDir();
  GltfWriter g;
  int white = g.material(GltfWriter::diffuse(glm::vec3(1.f)));
  int glass = g.material(GltfWriter::glass(1.5f));
  // An open box (five faces: many bounces inside), a diffuse sphere in it, a glass sphere.
  g.quad({-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, white);
  g.quad({-1, 0, -1}, {-1, 2, -1}, {1, 2, -1}, {1, 0, -1}, white);
  g.quad({-1, 0, -1}, {-1, 0, 1}, {-1, 2, 1}, {-1, 2, -1}, white);
  g.quad({1, 0, -1}, {1, 2, -1}, {1, 2, 1}, {1, 0, 1}, white);
  g.quad({-1, 2, -1}, {-1, 2, 1}, {1, 2, 1}, {1, 2, -1}, white);
  g.sphere({-0.4f, 0.5f, 0.f}, 0.45f, white);
  g.sphere({0.5f, 0.6f, 0.3f}, 0.4f, glass);
  g.camera({0.3f, 1.2f, 4.f}, {0.f, 0.9f, 0.f}, 0.8f);
  std::string path = (d / "furnace.gltf").string();
  g.write(path);
  const float kEnv = 0.5f;
  scene::Environment env = uniformEnvironment(kEnv);
  Rendered r = renderFile(path, 32, 64, 1, &env);
  ASSERT_EQ(r.film.samples, 64u);
  EXPECT_EQ(r.film.droppedSamples, 0u);
  // Image mean: 32*32*64 paths; per-pixel means: 64 paths each (loose, catches local bias).
  EXPECT_NEAR(mean(r.film.combined), kEnv, 0.01 * kEnv);
  // 4x4-pixel blocks (1024 paths each): within 5 standard errors (estimated from the spread
  // of the block's 48 pixel values) plus 1%.
  for (int by = 0; by < 8; ++by)
    for (int bx = 0; bx < 8; ++bx) {
      double s = 0, s2 = 0;
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x)
          for (int c = 0; c < 3; ++c) {
            double v = r.film.combined[((by * 4 + y) * 32 + bx * 4 + x) * 3 + c];
            s += v;
            s2 += v * v;
          }
      double m = s / 48, stderr_ = std::sqrt(std::max(0.0, s2 / 48 - m * m) / 16);
      EXPECT_NEAR(m, kEnv, 5 * stderr_ + 0.01 * kEnv) << "block " << bx << "," << by;
    }
  fs::remove_all(d);
}

TEST(PathIntegrator, DiffusePlaneUnderSquareEmitterMatchesAnalyticIrradiance) {
  fs::path d = tempDir();
  GltfWriter g;
  const float rho = 0.6f, le = 5.f, h = 0.8f, half = 0.25f;
  int plane = g.material(GltfWriter::diffuse(glm::vec3(rho)));
  int light = g.material(GltfWriter::emitter(glm::vec3(le), false));
  g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, plane);
  // Facing down (-Y): counter-clockwise seen from below.
  std::vector<glm::dvec3> poly = {
      {-half, h, -half}, {half, h, -half}, {half, h, half}, {-half, h, half}};
  g.quad(poly[0], poly[1], poly[2], poly[3], light);
  g.camera({0.f, 2.5f, 2.5f}, {0.f, 0.f, 0.f}, 0.9f);
  std::string path = (d / "plane.gltf").string();
  g.write(path);
  const uint32_t size = 32;
  Rendered r = renderFile(path, size, 256);
  double sumRatio = 0;
  int n = 0;
  for (uint32_t py = 0; py < size; ++py)
    for (uint32_t px = 0; px < size; ++px) {
      // Expected: rho/pi * E on the plane; pixels where a sub-ray meets the emitter (its dark
      // back) are skipped.
      double expect =
          groundPixel(r.camera, size, px, py, [&](glm::vec3 q, glm::vec3 o, glm::vec3 dir) {
            glm::vec3 ql = o + ((h - o.y) / dir.y) * dir;
            if (std::abs(ql.x) <= half + 0.02f && std::abs(ql.z) <= half + 0.02f) return -1.0;
            return rho / M_PI * le * polygonIrradiance(glm::dvec3(q), {0, 1, 0}, poly);
          });
      if (expect < 0.02) continue;
      float got = r.film.combined[(py * size + px) * 3 + 1];
      EXPECT_NEAR(got, expect, 0.08 * expect) << "pixel " << px << "," << py;
      EXPECT_NEAR(r.film.indirect[(py * size + px) * 3 + 1], 0.f, 1e-6);
      sumRatio += got / expect;
      ++n;
    }
  ASSERT_GT(n, 300);
  EXPECT_NEAR(sumRatio / n, 1.0, 0.005);
  fs::remove_all(d);
}

// An emissive texture lights the scene by its texels: the square emitter of the test above with
// a 2 x 1 emissive texture, white on its -x half and black on its +x half, gives the plane the
// irradiance of the -x half alone (light sampling picks triangles by the power of their own
// part of the texture: src/scene/emissive.cpp).
TEST(PathIntegrator, EmissiveTextureLightsByItsTexels) {
  fs::path d = tempDir();
  GltfWriter g;
  const float rho = 0.6f, le = 5.f, h = 0.8f, half = 0.25f;
  int plane = g.material(GltfWriter::diffuse(glm::vec3(rho)));
  auto emitter = GltfWriter::emitter(glm::vec3(le), false);
  emitter["emissiveTexture"] = {{"index", g.nearestTexture(2, 1, {255, 255, 255, 255, 0, 0, 0, 255})}};
  int light = g.material(emitter);
  g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, plane);
  // Facing down (-Y); u runs along +x.
  g.quad({-half, h, -half}, {half, h, -half}, {half, h, half}, {-half, h, half}, light);
  std::vector<glm::dvec3> lit = {{-half, h, -half}, {0, h, -half}, {0, h, half}, {-half, h, half}};
  g.camera({0.f, 2.5f, 2.5f}, {0.f, 0.f, 0.f}, 0.9f);
  std::string path = (d / "textured_emitter.gltf").string();
  g.write(path);
  const uint32_t size = 32;
  Rendered r = renderFile(path, size, 256);
  double sumRatio = 0, sumLeft = 0, sumRight = 0;
  int n = 0;
  for (uint32_t py = 0; py < size; ++py)
    for (uint32_t px = 0; px < size; ++px) {
      double expect =
          groundPixel(r.camera, size, px, py, [&](glm::vec3 q, glm::vec3 o, glm::vec3 dir) {
            glm::vec3 ql = o + ((h - o.y) / dir.y) * dir;
            if (std::abs(ql.x) <= half + 0.02f && std::abs(ql.z) <= half + 0.02f) return -1.0;
            return rho / M_PI * le * polygonIrradiance(glm::dvec3(q), {0, 1, 0}, lit);
          });
      if (expect < 0.02) continue;
      float got = r.film.combined[(py * size + px) * 3 + 1];
      EXPECT_NEAR(got, expect, 0.25 * expect) << "pixel " << px << "," << py;
      sumRatio += got / expect;
      (px < size / 2 ? sumLeft : sumRight) += got;
      ++n;
    }
  std::printf("textured emitter: mean ratio to analytic %.4f over %d pixels\n", sumRatio / n, n);
  ASSERT_GT(n, 200);  // the pixels the lit half reaches (270 at this size)
  EXPECT_NEAR(sumRatio / n, 1.0, 0.01);
  EXPECT_GT(sumLeft, 1.5 * sumRight);  // the lit half is on the left (-x)
  fs::remove_all(d);
}

// COLOR_0 multiplies the base colour and a slot with texCoord 1 reads TEXCOORD_1: diffuse
// quads facing the camera under a uniform environment of radiance 1 show their albedo.
TEST(PathIntegrator, VertexColorsAndSecondUvSetShade) {
  fs::path d = tempDir();
  GltfWriter g;
  int white = g.material(GltfWriter::diffuse(glm::vec3(1.f)));
  auto textured = GltfWriter::diffuse(glm::vec3(1.f));
  textured["pbrMetallicRoughness"]["baseColorTexture"] = {
      {"index", g.nearestTexture(2, 1, {255, 0, 0, 255, 0, 255, 0, 255})}, {"texCoord", 1}};
  int uv1 = g.material(textured);
  // Left quad: red at x = -1.1, blue at x = -0.1 (COLOR_0); right quad: TEXCOORD_1 is
  // TEXCOORD_0 mirrored in u, so its -x half shows the texture's right texel (green).
  g.quad({-1.1f, -0.5f, 0}, {-0.1f, -0.5f, 0}, {-0.1f, 0.5f, 0}, {-1.1f, 0.5f, 0}, white);
  const glm::vec4 red(1, 0, 0, 1), blue(0, 0, 1, 1);
  g.vertexColors({red, blue, blue, red});
  g.quad({0.1f, -0.5f, 0}, {1.1f, -0.5f, 0}, {1.1f, 0.5f, 0}, {0.1f, 0.5f, 0}, uv1);
  g.texCoords1({{1, 0}, {0, 0}, {0, 1}, {1, 1}});
  g.camera({0.f, 0.f, 3.f}, {0.f, 0.f, 0.f}, 0.8f);
  std::string path = (d / "attributes.gltf").string();
  g.write(path);
  const uint32_t size = 32;
  scene::Environment env = uniformEnvironment(1.f);
  Rendered r = renderFile(path, size, 64, 1, &env);
  const float pixel = 2 * 3 * std::tan(0.4f) / size;  // world size of a pixel at z = 0
  int checked = 0;
  for (uint32_t py = 0; py < size; ++py)
    for (uint32_t px = 0; px < size; ++px) {
      glm::vec3 o, dir;
      cameraRay(r.camera, size, px + 0.5f, py + 0.5f, o, dir);
      glm::vec3 q = o - (o.z / dir.z) * dir;
      if (std::abs(q.y) > 0.5f - pixel) continue;
      glm::vec3 expect;
      if (q.x > -1.1f + pixel && q.x < -0.1f - pixel)
        expect = glm::mix(glm::vec3(red), glm::vec3(blue), q.x + 1.1f);
      else if (q.x > 0.1f + pixel && std::abs(q.x - 0.6f) > pixel && q.x < 1.1f - pixel)
        expect = q.x < 0.6f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
      else
        continue;
      const float* c = &r.film.combined[(py * size + px) * 3];
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(c[k], expect[k], 0.03f) << "pixel " << px << "," << py << " channel " << k;
      ++checked;
    }
  EXPECT_GT(checked, 150);
  fs::remove_all(d);
}

TEST(PathIntegrator, PunctualLightsGiveAnalyticIrradiance) {
  fs::path d = tempDir();
  const float rho = 0.5f;
  for (const char* type : {"point", "directional", "spot"}) {
    const bool directional = std::string(type) == "directional", spot = std::string(type) == "spot";
    GltfWriter g;
    int plane = g.material(GltfWriter::diffuse(glm::vec3(rho)));
    g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, plane);
    if (directional)  // pointing down and towards -z, 60 degrees from the normal
      g.light(
          {{"type", "directional"},
           {"intensity", 683.0 * 2.0},
           {"_rotation", {-std::sin(M_PI / 6 + M_PI / 4), 0, 0, std::cos(M_PI / 6 + M_PI / 4)}}});
    else if (spot)  // straight down from (0.2, 1.2, 0): glTF lights point along local -Z
      g.light({{"type", "spot"},
               {"intensity", 683.0 * 3.0},
               {"spot", {{"innerConeAngle", 0.3}, {"outerConeAngle", 0.6}}},
               {"_translation", {0.2, 1.2, 0.0}},
               {"_rotation", {-std::sin(M_PI / 4), 0, 0, std::cos(M_PI / 4)}}});
    else
      g.light({{"type", "point"}, {"intensity", 683.0 * 3.0}, {"_translation", {0.3, 1.0, -0.2}}});
    g.camera({0.f, 2.5f, 2.5f}, {0.f, 0.f, 0.f}, 0.9f);
    std::string path = (d / "punctual.gltf").string();
    g.write(path);
    const uint32_t size = 24;
    Rendered r = renderFile(path, size, 256);
    ASSERT_EQ(r.scene.lights.size(), 1u);
    const gpu::scene::PunctualLight l = r.scene.lights[0];
    for (uint32_t py = 0; py < size; ++py)
      for (uint32_t px = 0; px < size; ++px) {
        double expect = groundPixel(
            r.camera, size, px, py,
            [&](glm::vec3 q, glm::vec3, glm::vec3) {
              if (directional) return rho / M_PI * l.intensity.y * std::max(0.f, -l.direction.y);
              glm::vec3 v = l.position - q;
              double falloff = 1.0;
              if (spot) {  // glTF's smooth cone falloff, squared
                double cd = glm::dot(l.direction, -glm::normalize(v));
                double a =
                    glm::clamp((cd - std::cos(0.6)) / (std::cos(0.3) - std::cos(0.6)), 0.0, 1.0);
                falloff = a * a;
              }
              return rho / M_PI * l.intensity.y * falloff * std::max(0.f, v.y / glm::length(v)) /
                     glm::dot(v, v);
            },
            16);
        if (expect < 0) continue;
        float got = r.film.combined[(py * size + px) * 3 + 1];
        // Punctual lights: the only noise is the pixel jitter (256 samples vs a 16x16 quadrature).
        EXPECT_NEAR(got, expect, 0.02 * expect + 1e-4) << type << " pixel " << px << "," << py;
      }
    if (directional) {
      EXPECT_NEAR(-r.scene.lights[0].direction.y, std::cos(M_PI / 3), 1e-4);
    }
  }
  fs::remove_all(d);
}

TEST(PathIntegrator, FixedSeedIsDeterministicAndLayersAddUp) {
  std::string cornell = test::referencePath("cornell/cornell.gltf");
  Rendered a = renderFile(cornell, 16, 4, 7);
  Rendered b = renderFile(cornell, 16, 4, 7);
  Rendered c = renderFile(cornell, 16, 4, 8);
  EXPECT_EQ(a.film.combined, b.film.combined);
  EXPECT_EQ(a.film.depth, b.film.depth);
  EXPECT_NE(a.film.combined, c.film.combined);
  for (size_t i = 0; i < a.film.combined.size(); ++i)
    ASSERT_NEAR(a.film.combined[i], a.film.direct[i] + a.film.indirect[i],
                1e-5f * (1 + a.film.combined[i]));
  EXPECT_GT(mean(a.film.indirect), 0.05 * mean(a.film.combined));  // the box interreflects
}

// Batching groups samples into submissions differently but never changes which samples run.
TEST(PathIntegrator, BatchingDoesNotChangeTheImage) {
  const std::string cornell = test::referencePath("cornell/cornell.gltf");
  render::RenderStats one, many;
  // batchTargetS 0: one sample per submission; 100: 1, then the other 11 in one submission.
  Rendered a = renderFile(cornell, 16, 12, 5, nullptr, pt::Mode::Path, 0.0, &one);
  Rendered b = renderFile(cornell, 16, 12, 5, nullptr, pt::Mode::Path, 100.0, &many);
  EXPECT_EQ(one.submissions, 12u);
  EXPECT_EQ(many.submissions, 2u);
  EXPECT_EQ(a.film.samples, 12u);
  EXPECT_EQ(a.film.combined, b.film.combined);
  EXPECT_EQ(a.film.albedo, b.film.albedo);
}

// The viewer's slices (pixel bands, one sample each) add the same samples as whole units.
TEST(PathIntegrator, SlicedUnitsGiveTheSameImage) {
  auto& ctx = test::context();
  const scene::Scene sc = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  const scene::Camera cam = scene::selectCamera(sc, "", 1.f);
  scene::GpuScene gs(ctx, sc, nullptr);
  bvh::Bvh tree = bvh::buildGpu(ctx, gs.vertices, gs.triangles, gs.triangleCount);
  pt::RenderSettings s;
  s.width = 19;  // odd: bands split rows
  s.height = 13;
  s.spp = 5;
  s.seed = 9;
  render::RenderStats whole, sliced;
  const render::FilmLayers a = pt::render(ctx, gs, tree, cam, s, {}, &whole);
  s.batchTargetS = 1e-9;  // every unit in as many slices as the integrator allows
  s.sliceUnits = true;
  std::vector<render::Progress> seen;
  const render::FilmLayers b = pt::render(
      ctx, gs, tree, cam, s, [&](const render::Progress& p) { seen.push_back(p); }, &sliced);
  EXPECT_EQ(sliced.units, 5u);
  EXPECT_EQ(sliced.submissions, 5u * pt::PathIntegrator::kMaxSlicesPerUnit);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.combined, b.combined);
  EXPECT_EQ(a.albedo, b.albedo);
  EXPECT_EQ(a.depth, b.depth);
  // Progress inside a unit counts its slices.
  ASSERT_GT(seen.size(), 2u);
  EXPECT_EQ(seen[0].units, 0u);
  EXPECT_DOUBLE_EQ(seen[0].unitFraction, 1.0 / pt::PathIntegrator::kMaxSlicesPerUnit);
}

// A film that is a window of a larger image (--crop) renders exactly the image's pixels
// there: camera rays, pixel filter and random streams are those of the whole image.
TEST(PathIntegrator, CropWindowEqualsTheWholeImageBitForBit) {
  auto& ctx = test::context();
  const scene::Scene sc = scene::loadScene(test::referencePath("cornell/cornell.gltf"));
  scene::Camera cam = scene::selectCamera(sc, "", 1.f);
  scene::GpuScene gs(ctx, sc, nullptr);
  bvh::Bvh tree = bvh::buildGpu(ctx, gs.vertices, gs.triangles, gs.triangleCount);
  pt::RenderSettings s;
  s.width = 37;  // odd sizes: rows of the window do not align with the image's
  s.height = 29;
  s.spp = 3;
  s.seed = 11;
  const render::FilmLayers whole = pt::render(ctx, gs, tree, cam, s);
  const uint32_t x0 = 9, y0 = 5, w = 17, h = 13;
  cam.window = {x0, y0, s.width, s.height};
  s.width = w;
  s.height = h;
  const render::FilmLayers crop = pt::render(ctx, gs, tree, cam, s);
  ASSERT_EQ(crop.width, int(w));
  auto window = [&](const std::vector<float>& layer, int channels) {
    std::vector<float> out;
    for (uint32_t y = y0; y < y0 + h; ++y)
      for (uint32_t x = x0; x < x0 + w; ++x)
        for (int c = 0; c < channels; ++c) out.push_back(layer[(y * whole.width + x) * channels + c]);
    return out;
  };
  EXPECT_EQ(crop.combined, window(whole.combined, 3));
  EXPECT_EQ(crop.direct, window(whole.direct, 3));
  EXPECT_EQ(crop.indirect, window(whole.indirect, 3));
  EXPECT_EQ(crop.albedo, window(whole.albedo, 3));
  EXPECT_EQ(crop.normal, window(whole.normal, 3));
  EXPECT_EQ(crop.depth, window(whole.depth, 1));
  EXPECT_GT(mean(crop.combined), 0.0);
}

TEST(PathIntegrator, PreviewIsAlbedoTimesHeadlightCosine) {
  fs::path d = tempDir();
  GltfWriter g;
  glm::vec3 albedo(0.2f, 0.5f, 0.8f);
  g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, g.material(GltfWriter::diffuse(albedo)));
  g.camera({0.f, 2.f, 2.f}, {0.f, 0.f, 0.f}, 0.5f);
  std::string path = (d / "preview.gltf").string();
  g.write(path);
  Rendered r = renderFile(path, 8, 64, 1, nullptr, pt::Mode::Preview);
  for (uint32_t py = 0; py < 8; ++py)
    for (uint32_t px = 0; px < 8; ++px) {
      glm::vec3 o, dir;
      cameraRay(r.camera, 8, px + 0.5f, py + 0.5f, o, dir);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(r.film.combined[(py * 8 + px) * 3 + c], albedo[c] * std::abs(dir.y), 0.01);
      EXPECT_NEAR(r.film.normal[(py * 8 + px) * 3 + 1], 1.f, 1e-5);
      EXPECT_NEAR(r.film.albedo[(py * 8 + px) * 3 + 2], albedo[2], 1e-5);
    }
  fs::remove_all(d);
}

// The denoisers' first-hit guides look into a mirror (pt_trace.comp, CameraPath): a floor
// mirror of base colour 0.9 reflecting a blue wall shows the wall's albedo times the tint, the
// wall's normal and the depth of its virtual image: the floor mirrors the wall z = -3 onto
// itself, so that is where the camera ray, unbent, meets that plane. With the wall a lamp,
// its pixels saw light.
TEST(PathIntegrator, FirstHitGuidesLookThroughAMirror) {
  fs::path d = tempDir();
  const glm::vec3 wallColour(0.2f, 0.5f, 0.8f);
  for (bool lamp : {false, true}) {
    GltfWriter g;
    g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4},
           g.material({{"pbrMetallicRoughness",
                        {{"baseColorFactor", {0.9, 0.9, 0.9, 1.0}}, {"metallicFactor", 1.0}, {"roughnessFactor", 0.0}}}}));
    g.quad({-20, 0, -3}, {20, 0, -3}, {20, 20, -3}, {-20, 20, -3},
           g.material(lamp ? GltfWriter::emitter(glm::vec3(2.f), true) : GltfWriter::diffuse(wallColour)));
    g.camera({0.f, 2.f, 2.f}, {0.f, 0.f, 0.f}, 0.5f);
    const std::string path = (d / "mirror.gltf").string();
    g.write(path);
    const scene::Environment sky = uniformEnvironment(0.5f);
    Rendered r = renderFile(path, 8, 16, 1, &sky);
    for (uint32_t i = 0; i < 64; ++i) {
      glm::vec3 o, dir;
      cameraRay(r.camera, 8, i % 8 + 0.5f, i / 8 + 0.5f, o, dir);
      const glm::vec3 wallPoint = o + dir * ((-3.f - o.z) / dir.z);
      const float virtualDepth = glm::dot(wallPoint - o, glm::normalize(glm::vec3(0.f, -2.f, -2.f)));
      if (lamp) {
        EXPECT_NEAR(r.film.light[i], 1.f, 1e-6) << i;
        continue;
      }
      // The mirror's tint is its directional albedo (lib/bsdf.glsl denoiseAlbedo): its base
      // colour to 1 %; the Lambertian wall's is its base colour.
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.film.albedo[3 * i + c], 0.9f * wallColour[c], 0.01f * wallColour[c]) << i;
      EXPECT_NEAR(r.film.normal[3 * i + 2], 1.f, 1e-3) << i;  // the wall's, facing the reflected ray
      EXPECT_EQ(r.film.light[i], 0.f) << i;
      EXPECT_NEAR(r.film.depth[i], virtualDepth, 0.01f * virtualDepth) << i;  // the mirror's: 2.3-3.7
    }
  }
  fs::remove_all(d);
}

// The direct layer counts from the first surface that is not near-specular, as OSR's does
// (pt_trace.comp addLight): the floor mirror of the test above reflects a diffuse wall that
// a sun lights head-on, so its pixels' direct light is the tint times the wall's radiance,
// albedo / pi x 2 (exact: a delta light, a uniformly lit wall). Counted from the mirror,
// it was all indirect.
TEST(PathIntegrator, DirectLayerStartsPastMirrors) {
  fs::path d = tempDir();
  const glm::vec3 wallColour(0.2f, 0.5f, 0.8f);
  GltfWriter g;
  g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4},
         g.material({{"pbrMetallicRoughness",
                      {{"baseColorFactor", {0.9, 0.9, 0.9, 1.0}}, {"metallicFactor", 1.0}, {"roughnessFactor", 0.0}}}}));
  g.quad({-20, 0, -3}, {20, 0, -3}, {20, 20, -3}, {-20, 20, -3}, g.material(GltfWriter::diffuse(wallColour)));
  g.light({{"type", "directional"}, {"intensity", 683.0 * 2.0}});  // along -z, onto the wall
  g.camera({0.f, 2.f, 2.f}, {0.f, 0.f, 0.f}, 0.5f);
  const std::string path = (d / "mirror_sun.gltf").string();
  g.write(path);
  Rendered r = renderFile(path, 8, 16);
  for (uint32_t i = 0; i < 64; ++i)
    for (int c = 0; c < 3; ++c) {
      const float expected = 0.9f * wallColour[c] / float(M_PI) * 2.f;
      EXPECT_NEAR(r.film.direct[3 * i + c], expected, 0.015f * expected) << i << " " << c;
      // Little else: the wall sees its own reflection only at grazing angles.
      EXPECT_LT(r.film.indirect[3 * i + c], 0.5f * expected) << i << " " << c;
    }
  fs::remove_all(d);
}

TEST(PathIntegrator, AlphaMaskIsSeenThroughAndCastsNoShadowThroughHoles) {
  fs::path d = tempDir();
  GltfWriter g;
  // Ground: red only. Masked quad at y = 1: green only, its texture opaque on the left half
  // (u < 0.5) and a hole on the right. The sun shines straight down.
  int ground = g.material(GltfWriter::diffuse({0.5f, 0.f, 0.f}));
  auto masked = GltfWriter::diffuse({0.f, 0.5f, 0.f});
  masked["pbrMetallicRoughness"]["baseColorTexture"] = {
      {"index", g.texture(2, 1, {255, 255, 255, 255, 255, 255, 255, 0})}};
  masked["alphaMode"] = "MASK";
  masked["alphaCutoff"] = 0.5;
  int quadMat = g.material(masked);
  g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, ground);
  g.quad({-2, 1, 2}, {2, 1, 2}, {2, 1, -2}, {-2, 1, -2}, quadMat);  // u along +x, facing up
  g.light({{"type", "directional"},
           {"intensity", 683.0 * 2.0},
           {"_rotation", {-std::sin(M_PI / 4), 0, 0, std::cos(M_PI / 4)}}});
  g.camera({0.f, 3.f, 0.001f}, {0.f, 0.f, 0.f}, 0.5f);
  std::string path = (d / "alpha.gltf").string();
  g.write(path);
  const uint32_t size = 16;
  Rendered r = renderFile(path, size, 16);
  const double radiance = 0.5 / M_PI * 2.0;  // albedo / pi * irradiance (lux / 683)
  for (uint32_t py = 2; py < size - 2; ++py) {
    // Left columns: the quad's green top; right columns: the red ground through the hole, lit
    // through the hole (the shadow ray must skip the masked texels too).
    for (uint32_t px : {2u, 5u}) {
      const float* c = &r.film.combined[(py * size + px) * 3];
      EXPECT_NEAR(c[1], radiance, 0.01) << px << "," << py;
      EXPECT_NEAR(c[0], 0.f, 1e-6) << px << "," << py;
    }
    for (uint32_t px : {10u, 13u}) {
      const float* c = &r.film.combined[(py * size + px) * 3];
      EXPECT_NEAR(c[0], radiance, 0.01) << px << "," << py;
    }
  }
  fs::remove_all(d);
}

// Blended textures converge to their coverage in camera and shadow rays alike; OPAQUE ignores
// alpha (test::writeCoverageScene has the analytic values).
TEST(PathIntegrator, AlphaBlendConvergesToCoverageOpaqueIgnoresAlpha) {
  fs::path d = tempDir();
  const double radiance = 0.5 / M_PI * 2.0;
  for (const char* mode : {"BLEND", "OPAQUE"}) {
    std::string path = (d / (std::string(mode) + ".gltf")).string();
    test::writeCoverageScene(path, mode);
    const uint32_t size = 16;
    Rendered r = renderFile(path, size, 256);
    bool blend = std::string(mode) == "BLEND";
    // Left (alpha 0.75) and right (0.25) halves, a column clear of the texel edge and image
    // border: 6 x 12 pixels x 256 samples each.
    for (int side = 0; side < 2; ++side) {
      double alpha = blend ? (side == 0 ? 191 / 255.0 : 64 / 255.0) : 1.0;
      double red = 0, green = 0;
      int n = 0;
      for (uint32_t py = 2; py < size - 2; ++py)
        for (uint32_t px = side == 0 ? 1u : 9u; px < (side == 0 ? 7u : 15u); ++px, ++n) {
          red += r.film.combined[(py * size + px) * 3];
          green += r.film.combined[(py * size + px) * 3 + 1];
        }
      std::printf("%s side %d: green %.4f (expect %.4f) red %.4f (expect %.4f)\n", mode, side,
                  green / n, alpha * radiance, red / n, (1 - alpha) * (1 - alpha) * radiance);
      EXPECT_NEAR(green / n, alpha * radiance, 0.01 * radiance) << mode << " side " << side;
      EXPECT_NEAR(red / n, (1 - alpha) * (1 - alpha) * radiance, 0.01 * radiance)
          << mode << " side " << side;
    }
  }
  fs::remove_all(d);
}

// The default pixel filter against its closed form: an emitter of radiance 1 filling the image
// left of a vertical edge at image x = e (pixels) gives pixel column px the filter's mass left
// of e, CDF(e - px - 0.5). Cycles' Blackman-Harris at width 1 px spans 2 px (Cycles doubles the
// width of this window): with the edge at e = 5.96, column 5 gets 0.953 and column 6, wholly
// right of the edge, 0.025, where a box gives 0.964 and 0.
TEST(PathIntegrator, PixelFilterIsCyclesBlackmanHarris) {
  fs::path d = tempDir();
  GltfWriter g;
  int light = g.material(GltfWriter::emitter(glm::vec3(1.f), false));
  g.quad({-50, -50, 0}, {0, -50, 0}, {0, 50, 0}, {-50, 50, 0}, light);  // faces +Z
  const float cx = 0.13f, dist = 2.f, yfov = 0.5f;
  g.camera({cx, 0, dist}, {cx, 0, 0}, yfov);
  std::string path = (d / "edge.gltf").string();
  g.write(path);
  auto& ctx = test::context();
  scene::Scene sc = scene::loadScene(path);
  scene::Camera cam = scene::selectCamera(sc, "", 1.f);
  scene::GpuScene gs(ctx, sc);
  bvh::Bvh tree = bvh::buildGpu(ctx, gs.vertices, gs.triangles, gs.triangleCount);
  const uint32_t size = 16;
  pt::RenderSettings s;
  s.width = s.height = size;
  s.spp = 256;
  render::FilmLayers film = pt::render(ctx, gs, tree, cam, s);
  const double e = 0.5 * size * (1.0 - cx / (dist * std::tan(0.5 * yfov)));
  int partial = 0;
  for (uint32_t px = 0; px < size; ++px) {
    double expect = test::blackmanHarrisCdf(e - px - 0.5);
    partial += expect > 0.001 && expect < 0.999;
    for (uint32_t py = 0; py < size; ++py)
      // 256 samples stratified in x (Sobol): coverage within about 1/256.
      EXPECT_NEAR(film.combined[(py * size + px) * 3 + 1], expect, 0.01)
          << "pixel " << px << "," << py << ", edge at x = " << e;
  }
  EXPECT_EQ(partial, 2);  // the window reaches past the edge's own pixel
  fs::remove_all(d);
}
