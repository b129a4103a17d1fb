// Host twins of shaders/lib/scene.glsl; keep the two in step (tests/scene/test_scene_probe.cpp
// compares them).
#include "scene/surface.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/gtc/packing.hpp>

namespace osr::scene {

namespace {

constexpr float kPi = 3.14159265358979f;

int positiveMod(int i, int n) {
  int m = i - n * int(std::floor(float(i) / float(n)));
  if (m < 0) m += n;
  if (m >= n) m -= n;
  return m;
}

int wrap(int i, int size, uint32_t mode) {
  if (mode == gpu::kWrapClamp) return std::clamp(i, 0, size - 1);
  if (mode == gpu::kWrapMirror) {
    int m = positiveMod(i, 2 * size);
    return std::clamp(m < size ? m : 2 * size - 1 - m, 0, size - 1);
  }
  return std::clamp(positiveMod(i, size), 0, size - 1);
}

glm::vec4 texel(const Texture& t, int x, int y) {
  uint32_t v = t.texels[size_t(y) * t.width + x];
  return glm::vec4(v & 255u, (v >> 8) & 255u, (v >> 16) & 255u, v >> 24) / 255.0f;
}

glm::vec4 vertexColor(const gpu::VertexAttributes& a) {
  glm::vec2 rg = glm::unpackHalf2x16(a.colorRG), ba = glm::unpackHalf2x16(a.colorBA);
  return {rg.x, rg.y, ba.x, ba.y};
}

uint32_t hash(uint32_t x) { return gpu::sceneHash(x); }

uint32_t bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

}  // namespace

glm::vec3 srgbToLinear(glm::vec3 c) {
  glm::vec3 out;
  for (int k = 0; k < 3; ++k)
    out[k] = c[k] <= 0.04045f ? c[k] / 12.92f : std::pow((c[k] + 0.055f) / 1.055f, 2.4f);
  return out;
}

void vertexAttributes(const Scene& scene, const gpu::Triangle& t, glm::vec2 b, glm::vec2 uv0,
                      glm::vec4& uvs, glm::vec4& color) {
  uvs = glm::vec4(uv0, uv0);
  color = glm::vec4(1.0f);
  if (scene.attributes.empty()) return;
  const gpu::VertexAttributes &a0 = scene.attributes[t.v0], &a1 = scene.attributes[t.v1],
                              &a2 = scene.attributes[t.v2];
  float b0 = 1.0f - b.x - b.y;
  glm::vec2 uv1 = a0.uv1 * b0 + a1.uv1 * b.x + a2.uv1 * b.y;
  uvs = glm::vec4(uv0, uv1);
  color = vertexColor(a0) * b0 + vertexColor(a1) * b.x + vertexColor(a2) * b.y;
}

glm::vec4 texCoords(const Scene& s, const gpu::Triangle& t, glm::vec2 b, glm::vec4& color) {
  const gpu::Vertex &a = s.vertices[t.v0], &v1 = s.vertices[t.v1], &v2 = s.vertices[t.v2];
  glm::vec2 uv0 = glm::vec2(a.u, a.v) * (1.0f - b.x - b.y) + glm::vec2(v1.u, v1.v) * b.x +
                  glm::vec2(v2.u, v2.v) * b.y;
  glm::vec4 uvs;
  vertexAttributes(s, t, b, uv0, uvs, color);
  return uvs;
}

float materialAlpha(const Scene& scene, const gpu::Material& mat, glm::vec4 uvs, glm::vec4 color) {
  return mat.baseColor.a * sampleTexture(scene, mat.baseColorTexture, uvs).a * color.a;
}

float alphaHashNumber(uint32_t triangle, glm::vec3 origin, glm::vec3 invDir) {
  uint32_t h = hash(bits(origin.x) ^
                    hash(bits(origin.y) ^
                         hash(bits(origin.z) ^
                              hash(bits(invDir.x) ^
                                   hash(bits(invDir.y) ^ hash(bits(invDir.z) ^ hash(triangle)))))));
  return float(h >> 8) * (1.0f / 16777216.0f);
}

glm::vec4 sampleTexture(const Scene& scene, int texture, glm::vec4 uvs) {
  if (texture < 0) return glm::vec4(1.0f);
  glm::vec2 uv = (texture & gpu::kTextureTexCoord1) ? glm::vec2(uvs.z, uvs.w) : glm::vec2(uvs);
  return sampleTexture(scene, texture & gpu::kTextureIndexMask, uv);
}

glm::vec4 sampleTexture(const Scene& scene, int texture, glm::vec2 uv) {
  if (texture < 0) return glm::vec4(1.0f);
  const Texture& t = scene.textures[texture];
  int w = int(t.width), h = int(t.height);
  glm::vec2 st = uv * glm::vec2(w, h) - 0.5f;
  for (int k = 0; k < 2; ++k) st[k] = std::isnan(st[k]) ? 0.0f : std::clamp(st[k], -1e9f, 1e9f);
  if (t.wrap & gpu::kTextureNearest) st = glm::floor(st + 0.5f);
  glm::vec2 base = glm::floor(st);
  glm::vec2 f = st - base;
  int x0 = int(base.x), y0 = int(base.y);
  uint32_t wrapS = t.wrap & 3u, wrapT = (t.wrap >> 2) & 3u;
  int xa = wrap(x0, w, wrapS), xb = wrap(x0 + 1, w, wrapS);
  int ya = wrap(y0, h, wrapT), yb = wrap(y0 + 1, h, wrapT);
  glm::vec4 top = glm::mix(texel(t, xa, ya), texel(t, xb, ya), f.x);
  glm::vec4 bottom = glm::mix(texel(t, xa, yb), texel(t, xb, yb), f.x);
  return glm::mix(top, bottom, f.y);
}

SurfaceSample surfaceAt(const Scene& scene, uint32_t triangle, glm::vec2 b) {
  const gpu::Triangle& t = scene.triangles[triangle];
  const gpu::Vertex &v0 = scene.vertices[t.v0], &v1 = scene.vertices[t.v1],
                    &v2 = scene.vertices[t.v2];
  float b0 = 1.0f - b.x - b.y;
  SurfaceSample s;
  s.position = v0.position * b0 + v1.position * b.x + v2.position * b.y;
  glm::vec3 e1 = v1.position - v0.position, e2 = v2.position - v0.position;
  glm::vec3 ng = glm::cross(e1, e2);
  float ngLength = glm::length(ng);
  s.geometricNormal = ngLength > 0.0f ? ng / ngLength : glm::vec3(0, 0, 1);
  glm::vec3 n = v0.normal * b0 + v1.normal * b.x + v2.normal * b.y;
  float nLength = glm::length(n);
  s.shadingNormal = nLength > 1e-12f ? n / nLength : s.geometricNormal;
  glm::vec2 uv0(v0.u, v0.v), uv1(v1.u, v1.v), uv2(v2.u, v2.v);
  glm::vec4 color;
  vertexAttributes(scene, t, b, uv0 * b0 + uv1 * b.x + uv2 * b.y, s.uv, color);
  s.material = t.material;
  const gpu::Material& mat = scene.materials[t.material];
  glm::vec4 base = sampleTexture(scene, mat.baseColorTexture, s.uv);
  s.m.baseColor = glm::vec3(mat.baseColor) * srgbToLinear(glm::vec3(base)) * glm::vec3(color);
  s.m.alpha = mat.baseColor.a * base.a * color.a;
  glm::vec4 mr = sampleTexture(scene, mat.metallicRoughnessTexture, s.uv);
  s.m.roughness = mat.roughness * mr.g;
  s.m.metallic = mat.metallic * mr.b;
  s.m.emission =
      mat.emission * srgbToLinear(glm::vec3(sampleTexture(scene, mat.emissiveTexture, s.uv)));
  s.m.specular = mat.specular * sampleTexture(scene, mat.specularTexture, s.uv).a;
  s.m.specularColor = mat.specularColor *
                      srgbToLinear(glm::vec3(sampleTexture(scene, mat.specularColorTexture, s.uv)));
  s.m.ior = mat.ior;
  s.m.transmission = mat.transmission * sampleTexture(scene, mat.transmissionTexture, s.uv).r;
  s.m.doubleSided = (mat.flags & gpu::kMaterialDoubleSided) != 0;
  if (mat.normalTexture >= 0) {
    if (!scene.attributes.empty() && (mat.normalTexture & gpu::kTextureTexCoord1)) {
      uv0 = scene.attributes[t.v0].uv1;
      uv1 = scene.attributes[t.v1].uv1;
      uv2 = scene.attributes[t.v2].uv1;
    }
    glm::vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    float det = d1.x * d2.y - d1.y * d2.x;
    if (std::abs(det) > 1e-20f) {
      glm::vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
      glm::vec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
      glm::vec3 nn = s.shadingNormal;
      glm::vec3 tangent = dpdu - nn * glm::dot(nn, dpdu);
      float tLength = glm::length(tangent);
      if (tLength > 1e-20f) {
        tangent /= tLength;
        glm::vec3 bitangent = glm::cross(nn, tangent) *
                              (glm::dot(glm::cross(nn, tangent), dpdv) < 0.0f ? -1.0f : 1.0f);
        glm::vec3 tn = glm::vec3(sampleTexture(scene, mat.normalTexture, s.uv)) * 2.0f - 1.0f;
        tn.x *= mat.normalScale;
        tn.y *= mat.normalScale;
        glm::vec3 mapped = tangent * tn.x + bitangent * tn.y + nn * tn.z;
        float mLength = glm::length(mapped);
        if (mLength > 1e-12f) s.shadingNormal = mapped / mLength;
      }
    }
  }
  return s;
}

float coverage(const Scene& scene, uint32_t triangle, glm::vec2 b) {
  const gpu::Triangle& t = scene.triangles[triangle];
  const gpu::Material& mat = scene.materials[t.material];
  if ((mat.flags & (gpu::kMaterialAlphaMask | gpu::kMaterialAlphaBlend)) == 0) return 1.0f;
  glm::vec4 color;
  glm::vec4 uvs = texCoords(scene, t, b, color);
  float alpha = materialAlpha(scene, mat, uvs, color);
  if (mat.flags & gpu::kMaterialAlphaBlend) return std::clamp(alpha, 0.0f, 1.0f);
  return alpha < mat.alphaCutoff ? 0.0f : 1.0f;
}

bool alphaCutout(const Scene& scene, uint32_t triangle, glm::vec2 b, glm::vec3 rayOrigin,
                 glm::vec3 rayInvDir) {
  const gpu::Triangle& t = scene.triangles[triangle];
  const gpu::Material& mat = scene.materials[t.material];
  if ((mat.flags & (gpu::kMaterialAlphaMask | gpu::kMaterialAlphaBlend)) == 0) return false;
  glm::vec4 color;
  glm::vec4 uvs = texCoords(scene, t, b, color);
  float alpha = materialAlpha(scene, mat, uvs, color);
  if (mat.flags & gpu::kMaterialAlphaBlend)
    return alphaHashNumber(triangle, rayOrigin, rayInvDir) >= alpha;
  return alpha < mat.alphaCutoff;
}

glm::vec3 environmentDirection(glm::vec2 uv) {
  float phi = (uv.x - 0.5f) * 2.0f * kPi;
  float theta = uv.y * kPi;
  float st = std::sin(theta);
  return {st * std::cos(phi), std::cos(theta), st * std::sin(phi)};
}

glm::vec2 environmentUv(glm::vec3 dir) {
  return {0.5f + std::atan2(dir.z, dir.x) / (2.0f * kPi),
          std::acos(std::clamp(dir.y, -1.0f, 1.0f)) / kPi};
}

namespace {

glm::uvec2 environmentTexel(const Environment& env, glm::vec2 uv) {
  return {std::min(uint32_t(std::max(uv.x, 0.0f) * float(env.width)), env.width - 1),
          std::min(uint32_t(std::max(uv.y, 0.0f) * float(env.height)), env.height - 1)};
}

uint32_t search(const std::vector<float>& cdf, uint32_t first, uint32_t count, float u) {
  uint32_t lo = 0, hi = count - 1;
  while (lo < hi) {
    uint32_t mid = (lo + hi) / 2;
    if (cdf[first + mid] > u)
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

float step(const std::vector<float>& cdf, uint32_t first, uint32_t i) {
  return cdf[first + i] - (i > 0 ? cdf[first + i - 1] : 0.0f);
}

}  // namespace

glm::vec3 environmentRadiance(const Environment& env, glm::vec3 dir) {
  if (env.width == 0) return glm::vec3(0.0f);
  glm::uvec2 p = environmentTexel(env, environmentUv(dir));
  return glm::vec3(env.texels[size_t(p.y) * env.width + p.x]);
}

float environmentPdf(const Environment& env, const std::vector<float>& cdf, glm::vec3 dir) {
  uint32_t w = env.width, h = env.height;
  if (w == 0) return 0.0f;
  glm::uvec2 p = environmentTexel(env, environmentUv(dir));
  float sinTheta = std::sqrt(std::max(0.0f, 1.0f - dir.y * dir.y));
  if (sinTheta <= 0.0f) return 0.0f;
  return step(cdf, 0, p.y) * step(cdf, h + p.y * w, p.x) * float(w * h) /
         (2.0f * kPi * kPi * sinTheta);
}

glm::vec3 sampleEnvironment(const Environment& env, const std::vector<float>& cdf, glm::vec2 u,
                            float& pdf, glm::vec3& radiance) {
  uint32_t w = env.width, h = env.height;
  if (w == 0) {
    pdf = 0.0f;
    radiance = glm::vec3(0.0f);
    return {0, 1, 0};
  }
  uint32_t y = search(cdf, 0, h, u.y);
  uint32_t rowFirst = h + y * w;
  uint32_t x = search(cdf, rowFirst, w, u.x);
  float pRow = step(cdf, 0, y), pCol = step(cdf, rowFirst, x);
  float fy = pRow > 0.0f ? std::clamp((u.y - (cdf[y] - pRow)) / pRow, 0.0f, 1.0f) : 0.5f;
  float fx = pCol > 0.0f ? std::clamp((u.x - (cdf[rowFirst + x] - pCol)) / pCol, 0.0f, 1.0f) : 0.5f;
  glm::vec2 uv((float(x) + fx) / float(w), (float(y) + fy) / float(h));
  glm::vec3 dir = environmentDirection(uv);
  float sinTheta = std::sin(uv.y * kPi);
  pdf = sinTheta > 0.0f ? pRow * pCol * float(w * h) / (2.0f * kPi * kPi * sinTheta) : 0.0f;
  radiance = glm::vec3(env.texels[size_t(y) * w + x]);
  return dir;
}

}  // namespace osr::scene
