// Light selection, light sampling and the MIS pdfs of next-event estimation, shared by every
// integrator. One light is chosen uniformly among {all emissive triangles (then one by
// power), each punctual light, the environment}; the pdfs here are what a BSDF-sampled hit of
// the same light needs for the power heuristic (Veach 1997).
// Requires lib/scene.glsl and lib/sampling.glsl included before.
#ifndef OSR_LIB_LIGHTS_GLSL
#define OSR_LIB_LIGHTS_GLSL

const float kInfinity = 1.0 / 0.0;

struct LightSample {
  vec3 wi;         // unit, towards the light
  float distance;  // to the light point (kInfinity: directional / environment)
  vec3 radiance;   // arriving radiance (area, env) or irradiance-like intensity term (punctual)
  float pdf;       // solid-angle pdf including the light choice; 0 = no sample
  bool delta;      // punctual: no MIS
};

uint lightSlotCount() {
  return (gSceneInfo.emissiveCount > 0u ? 1u : 0u) + gSceneInfo.lightCount +
         (gSceneInfo.envWidth > 0u ? 1u : 0u);
}

// Emissive-triangle index whose triangle is `triangle` (gEmissive is sorted by triangle), or
// ~0u when that triangle is not in the light list (zero power).
uint findEmissive(uint triangle) {
  uint lo = 0u, hi = gSceneInfo.emissiveCount;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (gEmissive[mid].triangle < triangle) lo = mid + 1u; else hi = mid;
  }
  return lo < gSceneInfo.emissiveCount && gEmissive[lo].triangle == triangle ? lo : ~0u;
}

// Radiance a light sample at barycentrics b of triangle t sees leaving it: emission times the
// surface's coverage (a blended emitter is met by a fraction alpha of rays, a masked one not
// in its holes), so that light sampling and BSDF-sampled hits agree.
vec3 emissionAt(Triangle t, Material mat, vec2 b) {
  vec4 color;
  vec4 uvs = sceneTexCoords(t, b, color);
  vec3 e = mat.emission * srgbToLinear(sampleTexture(mat.emissiveTexture, uvs).rgb);
  if (sceneHas(kSceneFeatureAlphaTest) && (mat.flags & (kMaterialAlphaMask | kMaterialAlphaBlend)) != 0u)
    e *= materialCoverage(mat, materialAlpha(mat, uvs, color));
  return e;
}

// Solid-angle pdf with which next-event estimation picks point `p` (normal ng) on emissive
// triangle `triangle` as seen from `from`.
float emissivePdf(uint triangle, vec3 from, vec3 p, vec3 ng) {
  uint e = findEmissive(triangle);
  if (e == ~0u || gSceneInfo.emissivePower <= 0.0) return 0.0;
  vec3 d = p - from;
  float dist2 = dot(d, d);
  float cosL = abs(dot(ng, d)) * inversesqrt(dist2);
  if (cosL <= 0.0) return 0.0;
  float pChoose = gEmissive[e].power / gSceneInfo.emissivePower;
  return pChoose / gEmissive[e].area * dist2 / cosL / float(lightSlotCount());
}

float environmentLightPdf(vec3 dir) {
  if (gSceneInfo.envWidth == 0u) return 0.0;
  return environmentPdf(dir) / float(lightSlotCount());
}

bool sampleLight(vec3 p, vec3 u, out LightSample ls) {
  ls.wi = vec3(0.0, 1.0, 0.0);
  ls.distance = 0.0;
  ls.radiance = vec3(0.0);
  ls.pdf = 0.0;
  ls.delta = false;
  uint slots = lightSlotCount();
  if (slots == 0u) return false;
  uint slot = min(uint(u.x * float(slots)), slots - 1u);
  float pSlot = 1.0 / float(slots);
  if (gSceneInfo.emissiveCount > 0u) {
    if (slot == 0u) {
      // Emissive triangle by power: first cdf entry above u.y.
      uint lo = 0u, hi = gSceneInfo.emissiveCount - 1u;
      float uy = fract(u.x * float(slots));  // the slot choice left this uniform in [0, 1)
      while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (gEmissive[mid].cdf > uy) hi = mid; else lo = mid + 1u;
      }
      EmissiveTriangle e = gEmissive[lo];
      Triangle t = sceneTriangle(e.triangle);
      Vertex v0 = sceneVertex(t.v0), v1 = sceneVertex(t.v1), v2 = sceneVertex(t.v2);
      vec2 b = sampleTriangle(u.yz);
      vec3 q = v0.position * (1.0 - b.x - b.y) + v1.position * b.x + v2.position * b.y;
      vec3 ng = normalize(cross(v1.position - v0.position, v2.position - v0.position));
      vec3 d = q - p;
      float dist2 = dot(d, d);
      if (dist2 <= 0.0) return false;
      float dist = sqrt(dist2);
      ls.wi = d / dist;
      float cosL = dot(ng, -ls.wi);
      Material mat = sceneMaterial(t.material);
      bool emits = cosL > 0.0 || (mat.flags & kMaterialDoubleSided) != 0u;
      if (!emits || cosL == 0.0) return false;
      ls.distance = dist;
      ls.radiance = emissionAt(t, mat, b);
      ls.pdf = pSlot * (e.power / gSceneInfo.emissivePower) / e.area * dist2 / abs(cosL);
      return ls.pdf > 0.0;
    }
    slot -= 1u;
  }
  if (sceneHas(kSceneFeaturePunctual) && slot < gSceneInfo.lightCount) {
    PunctualLight l = gLights[slot];
    ls.delta = true;
    ls.pdf = pSlot;
    if (l.type == kLightDirectional) {
      ls.wi = -l.direction;
      ls.distance = kInfinity;
      ls.radiance = l.intensity;
      return true;
    }
    vec3 d = l.position - p;
    float dist2 = dot(d, d);
    if (dist2 <= 0.0) return false;
    ls.distance = sqrt(dist2);
    ls.wi = d / ls.distance;
    float atten = 1.0 / dist2;
    if (l.range > 0.0) {
      // glTF's recommended range window: smooth falloff to 0 at `range`.
      float r = ls.distance / l.range;
      atten *= clamp(1.0 - r * r * r * r, 0.0, 1.0);
    }
    if (l.type == kLightSpot) {
      float cd = dot(l.direction, -ls.wi);
      float scale = 1.0 / max(0.001, l.cosInner - l.cosOuter);
      float a = clamp((cd - l.cosOuter) * scale, 0.0, 1.0);
      atten *= a * a;
    }
    ls.radiance = l.intensity * atten;
    return atten > 0.0;
  }
  // Environment (the last slot exists only with a map).
  if (!sceneHas(kSceneFeatureEnvironment)) return false;
  float envPdf;
  vec3 envRadiance;
  ls.wi = sampleEnvironment(u.yz, envPdf, envRadiance);
  ls.distance = kInfinity;
  ls.radiance = envRadiance;
  ls.pdf = pSlot * envPdf;
  return ls.pdf > 0.0;
}

#endif
