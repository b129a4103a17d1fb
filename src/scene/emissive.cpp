#include "scene/emissive.h"

#include <cmath>
#include <map>

namespace osr::scene {

namespace {

// Mean linear colour of an sRGB texture: the emissive texture's share of a triangle's power
// (a triangle may cover any part of the texture; the mean keeps sampling unbiased wherever the
// texture is non-zero, only less well matched).
glm::vec3 meanLinear(const Texture& t) {
  if (t.texels.empty()) return glm::vec3(1.0f);
  glm::dvec3 sum(0.0);
  for (uint32_t texel : t.texels)
    for (int k = 0; k < 3; ++k) {
      double c = ((texel >> (8 * k)) & 255u) / 255.0;
      sum[k] += c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    }
  return glm::vec3(sum / double(t.texels.size()));
}

}  // namespace

void collectEmissive(Scene& scene) {
  scene.emissive.clear();
  std::map<int, glm::vec3> means;
  double total = 0.0;
  for (uint32_t i = 0; i < scene.triangles.size(); ++i) {
    const gpu::Triangle& t = scene.triangles[i];
    const gpu::Material& m = scene.materials[t.material];
    glm::vec3 emission = m.emission;
    if (m.emissiveTexture != gpu::kNoTexture) {
      auto it = means.find(m.emissiveTexture);
      if (it == means.end())
        it = means.emplace(m.emissiveTexture, meanLinear(scene.textures[m.emissiveTexture])).first;
      emission *= it->second;
    }
    float lum = luminance(emission);
    if (!(lum > 0.0f)) continue;
    glm::vec3 p0 = scene.vertices[t.v0].position, p1 = scene.vertices[t.v1].position,
              p2 = scene.vertices[t.v2].position;
    float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
    if (!(area > 0.0f)) continue;
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
