// C++ twins of shaders/lib/scene.glsl: the same arithmetic on the host, for tests (GPU results
// are checked against these) and CPU reference code (e.g. brute-force any-hit with alpha).
#pragma once
#include <glm/glm.hpp>

#include "scene/scene.h"

namespace osr::scene {

struct SurfaceMaterial {
  glm::vec3 baseColor{1.0f};
  float alpha = 1.0f;
  glm::vec3 emission{0.0f};
  float metallic = 0.0f;
  glm::vec3 specularColor{1.0f};
  float roughness = 1.0f;
  float specular = 1.0f;
  float ior = 1.5f;
  float transmission = 0.0f;
  bool doubleSided = false;
};

struct SurfaceSample {
  glm::vec3 position{0.0f};
  glm::vec3 geometricNormal{0.0f, 0.0f, 1.0f};
  glm::vec3 shadingNormal{0.0f, 0.0f, 1.0f};
  glm::vec4 uv{0.0f};  // TEXCOORD_0 (xy), TEXCOORD_1 (zw)
  uint32_t material = 0;
  SurfaceMaterial m;
};

glm::vec3 srgbToLinear(glm::vec3 c);
// Bilinear (nearest with kTextureNearest), wrap modes, raw RGBA in [0, 1]; kNoTexture gives
// white (sampleTexture in GLSL).
// `texture` is a texture index here; the overload below takes a material's texture reference
// (| kTextureTexCoord1) and both uv sets (TEXCOORD_0 in xy, TEXCOORD_1 in zw).
glm::vec4 sampleTexture(const Scene& scene, int texture, glm::vec2 uv);
glm::vec4 sampleTexture(const Scene& scene, int texture, glm::vec4 uvs);
// Barycentrics (b1, b2) weight v1 and v2; v0 gets 1 - b1 - b2.
SurfaceSample surfaceAt(const Scene& scene, uint32_t triangle, glm::vec2 b);
// True where the ray (origin, 1 / direction) goes on through the hit: a masked material's
// alpha below its cutoff, or a blended one's hash of the ray and triangle at or above alpha
// (osrAlphaCutout in GLSL).
bool alphaCutout(const Scene& scene, uint32_t triangle, glm::vec2 b, glm::vec3 rayOrigin,
                 glm::vec3 rayInvDir);
// The fraction of light the hit stops: 1 opaque, alpha blended, 0 or 1 masked.
float coverage(const Scene& scene, uint32_t triangle, glm::vec2 b);

// Environment mapping (see scene.glsl): uv in [0,1]^2 with v = 0 at the top (+Y).
glm::vec3 environmentDirection(glm::vec2 uv);
glm::vec2 environmentUv(glm::vec3 dir);
glm::vec3 environmentRadiance(const Environment& env, glm::vec3 dir);
// Solid-angle pdf of sampleEnvironment for `dir`, from the CDF tables of environmentCdf().
float environmentPdf(const Environment& env, const std::vector<float>& cdf, glm::vec3 dir);
// Returns the sampled direction; pdf and radiance written out.
glm::vec3 sampleEnvironment(const Environment& env, const std::vector<float>& cdf, glm::vec2 u,
                            float& pdf, glm::vec3& radiance);

}  // namespace osr::scene
