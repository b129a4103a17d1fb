#include "scene/emissive.h"

#include <algorithm>
#include <cmath>

#include "scene/surface.h"

namespace osr::scene {

namespace {

// Mean emitted radiance over triangle i: the material's emission where it is a constant,
// else (an emissive texture, or alpha that masks or blends the emitter) the average of
// surfaceAt's emission x coverage at the centroids of an n x n subdivision of the triangle,
// n = 4 per side of the texels its uvs cover (from 1 up to 16). Light sampling stays unbiased
// whatever this estimate is: a triangle left out (estimate 0) is still met by BSDF samples,
// with MIS weight 1 (lights.glsl emissivePdf is 0 for it).
glm::vec3 meanEmission(const Scene& scene, uint32_t i) {
  const gpu::Triangle& t = scene.triangles[i];
  const gpu::Material& m = scene.materials[t.material];
  bool alpha = (m.flags & (gpu::kMaterialAlphaMask | gpu::kMaterialAlphaBlend)) != 0;
  if (m.emissiveTexture == gpu::kNoTexture && !alpha) return m.emission;
  int n = 1;
  if (m.emissiveTexture != gpu::kNoTexture) {
    const Texture& tex = scene.textures[m.emissiveTexture & gpu::kTextureIndexMask];
    glm::vec4 a = surfaceAt(scene, i, {0.0f, 0.0f}).uv, b = surfaceAt(scene, i, {1.0f, 0.0f}).uv,
              c = surfaceAt(scene, i, {0.0f, 1.0f}).uv;
    bool set1 = (m.emissiveTexture & gpu::kTextureTexCoord1) != 0;
    glm::vec2 ua = set1 ? glm::vec2(a.z, a.w) : glm::vec2(a), ub = set1 ? glm::vec2(b.z, b.w) : glm::vec2(b),
              uc = set1 ? glm::vec2(c.z, c.w) : glm::vec2(c);
    glm::vec2 d1 = ub - ua, d2 = uc - ua;
    float texels = 0.5f * std::abs(d1.x * d2.y - d1.y * d2.x) * float(tex.width) * float(tex.height);
    // Clamped as a float: a texture of 65536 x 65536 on a large uv triangle gives more texels
    // than an int holds.
    n = std::isfinite(texels) ? int(std::clamp(std::ceil(4.0f * std::sqrt(texels)), 1.0f, 16.0f)) : 16;
  }
  // Centroids of the n^2 equal sub-triangles: (row j, column k) upright ones and, between
  // them, the inverted ones.
  glm::dvec3 sum(0.0);
  for (int j = 0; j < n; ++j)
    for (int k = 0; k + j < n; ++k)
      for (int flip = 0; flip < (k + j + 1 < n ? 2 : 1); ++flip) {
        glm::vec2 b = flip ? glm::vec2(k + 2.0f / 3.0f, j + 2.0f / 3.0f) / float(n)
                           : glm::vec2(k + 1.0f / 3.0f, j + 1.0f / 3.0f) / float(n);
        sum += glm::dvec3(surfaceAt(scene, i, b).m.emission * coverage(scene, i, b));
      }
  return glm::vec3(sum / double(n * n));
}

}  // namespace

void collectEmissive(Scene& scene) {
  scene.emissive.clear();
  double total = 0.0;
  for (uint32_t i = 0; i < scene.triangles.size(); ++i) {
    const gpu::Triangle& t = scene.triangles[i];
    const gpu::Material& m = scene.materials[t.material];
    if (!(luminance(m.emission) > 0.0f)) continue;
    glm::vec3 p0 = scene.vertices[t.v0].position, p1 = scene.vertices[t.v1].position,
              p2 = scene.vertices[t.v2].position;
    float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
    if (!(area > 0.0f)) continue;
    float lum = luminance(meanEmission(scene, i));
    if (!(lum > 0.0f)) continue;
    float sides = (m.flags & gpu::kMaterialDoubleSided) ? 2.0f : 1.0f;
    float power = lum * area * 3.14159265f * sides;
    scene.emissive.push_back({i, power, 0.0f, area});
    total += power;
  }
  double running = 0.0;
  for (gpu::EmissiveTriangle& e : scene.emissive) {
    running += e.power;
    e.cdf = float(running / total);
  }
  if (!scene.emissive.empty()) scene.emissive.back().cdf = 1.0f;
  scene.emissivePower = float(total);
}

}  // namespace osr::scene
