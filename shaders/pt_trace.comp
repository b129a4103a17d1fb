#version 460
// pt_trace: one sample per pixel for a range of pixels, added to the film's running sums.
// Inputs: Frame (camera, size, seed), the BVH, the scene; push: pixel range and sample index.
// Output: FilmPixel sums (shared/pt.h). A megakernel: each invocation follows its path to the
// end: on lavapipe, barriers between wavefront stages are expected to cost more than the
// divergence they remove (src/render/trace_pass.h has the reasoning; not measured).
//
// Path integrator (kIntegratorPath): camera rays jittered uniformly over the pixel (box
// filter); at each surface next-event estimation towards one light chosen uniformly among
// {all emissive triangles (then one by power), each punctual light, the environment},
// combined with BSDF sampling by the power heuristic (Veach 1997); delta lights and delta
// BSDF lobes take the one strategy that can sample them. Russian roulette from the fourth
// surface on, with survival min(max(throughput), 0.95); no fixed depth cap.
// Preview (kIntegratorPreview): primary hit only, baseColor x |cos| to the camera ray.
#extension GL_GOOGLE_include_directive : require
#include "shared/pt.h"
#include "shared/bsdf.h"

#define OSR_SCENE_BINDING kPtSceneBinding
#define OSR_SCENE_TEXEL_BINDING kPtSceneTexelBinding
// The scene's features (GpuScene::features): code for absent ones is compiled out.
layout(constant_id = kPtSpecSceneFeatures) const uint kSceneFeatures = kSceneFeatureAll;
#define OSR_SCENE_FEATURES kSceneFeatures
#include "lib/scene.glsl"
#define OSR_BVH_BINDING kPtBvhBinding
#define OSR_BVH_ALPHA_TEST
#include "lib/bvh_traverse.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#define OSR_BSDF_TRANSMISSION ((kSceneFeatures & kSceneFeatureTransmission) != 0u)
#include "lib/bsdf.glsl"
#include "lib/ray_offset.glsl"

layout(constant_id = kPtSpecIntegrator) const uint kIntegrator = kIntegratorPath;
layout(local_size_x = kPtWorkgroupSize) in;
layout(std430, binding = kPtBindingFilm) buffer Film { FilmPixel gFilm[]; };
layout(std430, binding = kPtBindingFrame) readonly buffer FrameBlock { Frame gFrame; };
layout(push_constant) uniform PushBlock { Push gPush; };

const float kInfinity = 1.0 / 0.0;

// ---- Lights ----------------------------------------------------------------------------------

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

vec3 emissionAt(Material mat, vec2 uv) {
  return mat.emission * srgbToLinear(sampleTexture(mat.emissiveTexture, uv).rgb);
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
      vec2 uv = vec2(v0.u, v0.v) * (1.0 - b.x - b.y) + vec2(v1.u, v1.v) * b.x + vec2(v2.u, v2.v) * b.y;
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
      ls.radiance = emissionAt(mat, uv);
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

// ---- Camera and film -------------------------------------------------------------------------

void cameraRay(uint x, uint y, vec2 jitter, out vec3 origin, out vec3 dir) {
  vec2 ndc = vec2((float(x) + jitter.x) / float(gFrame.width) * 2.0 - 1.0,
                  1.0 - (float(y) + jitter.y) / float(gFrame.height) * 2.0);
  vec3 local = vec3(ndc.x * gFrame.tanHalfFovY * gFrame.aspect, ndc.y * gFrame.tanHalfFovY, -1.0);
  origin = gFrame.cameraOrigin.xyz;
  dir = normalize(local.x * gFrame.cameraRight.xyz + local.y * gFrame.cameraUp.xyz +
                  local.z * gFrame.cameraBack.xyz);
}

struct Sample {
  vec3 direct;
  vec3 indirect;
  vec3 albedo;
  vec3 normal;
  float depth;
  bool hit;
};

BsdfParams bsdfParams(SurfaceMaterial m, bool front) {
  BsdfParams p;
  p.baseColor = m.baseColor;
  p.metallic = m.metallic;
  p.specularColor = m.specularColor;
  p.roughness = m.roughness;
  p.specular = m.specular;
  p.eta = front ? m.ior : 1.0 / m.ior;
  p.transmission = m.transmission;
  p._pad0 = 0.0;
  return p;
}

// Adds light that arrived after `bounces` surface interactions to the right film bucket.
void addLight(inout Sample s, uint bounces, vec3 l) {
  if (bounces <= 1u) s.direct += l; else s.indirect += l;
}

// The state of one path between bounces.
struct PathState {
  vec3 origin;
  vec3 dir;
  vec3 beta;       // throughput
  float prevPdf;   // BSDF pdf of the direction that led here (0: camera ray or delta lobe)
  vec3 prevPos;
  uint bounce;     // surfaces met so far
  Rng rng;
  uint pixel;
  uint sampleIndex;
  Sample s;
};

// Stratified 2-D sample for dimension pair `pair` of this path's sample (see sobolOwen2).
vec2 stratified2(PathState p, uint pair) {
  return sobolOwen2(p.sampleIndex, pcgHash(p.pixel ^ pcgHash(gFrame.seed + pair * 0x9e3779b9u)));
}

// The three numbers of the light sample (which = 0) or the BSDF sample (which = 1): stratified
// over the pixel's samples at the first surface, independent after it.
vec3 bounceRandom3(inout PathState p, uint which) {
  if (p.bounce != 0u) return rngNext3(p.rng);
  vec2 choice = stratified2(p, 1u);
  return vec3(which == 0u ? choice.x : choice.y, stratified2(p, 2u + which));
}

Sample emptySample() {
  Sample s;
  s.direct = vec3(0.0);
  s.indirect = vec3(0.0);
  s.albedo = vec3(0.0);
  s.normal = vec3(0.0);
  s.depth = 0.0;
  s.hit = false;
  return s;
}

// Starts sample `sampleIndex` of `pixel`: its random stream and jittered camera ray.
PathState startPath(uint pixel, uint sampleIndex) {
  PathState p;
  p.rng = rngInit(pixel, sampleIndex, gFrame.seed);
  p.pixel = pixel;
  p.sampleIndex = sampleIndex;
  cameraRay(pixel % gFrame.width, pixel / gFrame.width, stratified2(p, 0u), p.origin, p.dir);
  p.beta = vec3(1.0);
  p.prevPdf = 0.0;
  p.prevPos = p.origin;
  p.bounce = 0u;
  p.s = emptySample();
  return p;
}

// One bounce: finds the next surface, adds its emission and next-event estimate, samples the
// BSDF for the continuation. Returns true when the path has ended.
bool pathStep(inout PathState p) {
  Hit hit;
  if (!bvhClosestHit(p.origin, p.dir, 0.0, kInfinity, hit)) {
    if (sceneHas(kSceneFeatureEnvironment) && gSceneInfo.envWidth > 0u) {
      vec3 le = environmentRadiance(p.dir);
      float w = p.prevPdf > 0.0 ? powerHeuristic(p.prevPdf, environmentLightPdf(p.dir)) : 1.0;
      addLight(p.s, p.bounce, p.beta * w * le);
    }
    return true;
  }
  SurfaceSample surf = surfaceAt(hit.triangle, hit.barycentrics);
  vec3 wo = -p.dir;
  vec3 ng = surf.geometricNormal;
  vec3 ns = surf.shadingNormal;
  if (dot(ns, ng) < 0.0) ns = -ns;  // vertex normals disagreeing with the winding
  bool front = dot(ng, wo) > 0.0;
  if (!front) {
    ng = -ng;
    ns = -ns;
  }
  if (p.bounce == 0u) {
    p.s.hit = true;
    p.s.albedo = surf.m.baseColor;
    p.s.normal = ns;
    p.s.depth = dot(surf.position - gFrame.cameraOrigin.xyz, -gFrame.cameraBack.xyz);
  }
  // Emission (front faces, and back faces of double-sided materials).
  if ((front || surf.m.doubleSided) && any(greaterThan(surf.m.emission, vec3(0.0)))) {
    float w = 1.0;
    if (p.prevPdf > 0.0)
      w = powerHeuristic(p.prevPdf, emissivePdf(hit.triangle, p.prevPos, surf.position, ng));
    addLight(p.s, p.bounce, p.beta * w * surf.m.emission);
  }
  // Shading frame facing wo; where the shading normal puts wo below the horizon, use the
  // geometric normal rather than shade a direction the BSDF has no value for.
  if (dot(ns, wo) <= 1e-4) ns = ng;
  vec3 t, b;
  frameFromNormal(ns, t, b);
  vec3 woLocal = toLocal(wo, t, b, ns);
  BsdfParams bp = bsdfParams(surf.m, front);

  // Next-event estimation.
  LightSample ls;
  if (sampleLight(surf.position, bounceRandom3(p, 0u), ls)) {
    vec3 wiLocal = toLocal(ls.wi, t, b, ns);
    // Reject directions on different sides by the shading and geometric normals (light
    // leaks through shading-normal interpolation).
    if ((dot(ls.wi, ng) > 0.0) == (wiLocal.z > 0.0)) {
      float bsdfPdf;
      vec3 f = bsdfEval(bp, woLocal, wiLocal, bsdfPdf);
      if (any(greaterThan(f, vec3(0.0)))) {
        vec3 o = offsetRayOrigin(surf.position, dot(ls.wi, ng) > 0.0 ? ng : -ng);
        float tMax = ls.distance == kInfinity ? kInfinity : ls.distance * (1.0 - 1e-4);
        if (!bvhAnyHit(o, ls.wi, 0.0, tMax)) {
          float w = ls.delta ? 1.0 : powerHeuristic(ls.pdf, bsdfPdf);
          addLight(p.s, p.bounce + 1u, p.beta * f * ls.radiance * (w / ls.pdf));
        }
      }
    }
  }

  // Continue the path by sampling the BSDF.
  BsdfSample bs;
  if (!bsdfSample(bp, woLocal, bounceRandom3(p, 1u), bs)) return true;
  vec3 wi = toWorld(bs.wi, t, b, ns);
  if ((dot(wi, ng) > 0.0) != (bs.wi.z > 0.0)) return true;
  p.beta *= bs.weight;
  p.prevPdf = bs.delta ? 0.0 : bs.pdf;
  p.prevPos = surf.position;
  p.origin = offsetRayOrigin(surf.position, dot(wi, ng) > 0.0 ? ng : -ng);
  p.dir = wi;
  if (p.bounce >= 3u) {
    float survive = min(maxComponent(p.beta), 0.95);
    if (rngNext(p.rng) >= survive) return true;
    p.beta /= survive;
  }
  p.bounce += 1u;
  return !(maxComponent(p.beta) > 0.0);
}

Sample tracePreview(vec3 origin, vec3 dir) {
  Sample s = emptySample();
  Hit hit;
  if (!bvhClosestHit(origin, dir, 0.0, kInfinity, hit)) return s;
  SurfaceSample surf = surfaceAt(hit.triangle, hit.barycentrics);
  vec3 ns = surf.shadingNormal;
  if (dot(ns, dir) > 0.0) ns = -ns;
  s.hit = true;
  s.albedo = surf.m.baseColor;
  s.normal = ns;
  s.depth = dot(surf.position - gFrame.cameraOrigin.xyz, -gFrame.cameraBack.xyz);
  s.direct = surf.m.baseColor * abs(dot(ns, dir));
  return s;
}

// Adds one finished sample to the pixel's running sums (kept in registers until the end).
void accumulate(inout FilmPixel f, Sample s) {
  // A non-finite sample (never expected) would poison the pixel forever: drop its radiance
  // and count it in normal.w, which the host reports as dropped samples.
  vec3 l = s.direct + s.indirect;
  bool finite = !any(isnan(l)) && !any(isinf(l));
  f.combined += vec4(finite ? l : vec3(0.0), 1.0);
  f.direct.rgb += finite ? s.direct : vec3(0.0);
  f.indirect.rgb += finite ? s.indirect : vec3(0.0);
  f.albedo.rgb += s.albedo;
  f.normal.rgb += s.normal;
  f.normal.w += finite ? 0.0 : 1.0;
  f.depth += s.hit ? vec4(s.depth, 1.0, 0.0, 0.0) : vec4(0.0);
}

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  FilmPixel f = gFilm[pixel];
  if (kIntegrator == kIntegratorPreview) {
    for (uint i = 0u; i < gPush.sampleCount; ++i) {
      PathState p = startPath(pixel, gPush.sampleIndex + i);
      accumulate(f, tracePreview(p.origin, p.dir));
    }
  } else {
    // One flat loop over bounces of successive samples, so that a lane whose path ends starts
    // its next sample at once instead of idling until the longest path of its SIMD group ends
    // (path regeneration, Novak et al. 2010). Sample i uses the random stream of sample index
    // sampleIndex + i: the image does not depend on how samples are split into dispatches.
    uint i = 0u;
    PathState p = startPath(pixel, gPush.sampleIndex);
    while (true) {
      if (pathStep(p)) {
        accumulate(f, p.s);
        if (++i == gPush.sampleCount) break;
        p = startPath(pixel, gPush.sampleIndex + i);
      }
    }
  }
  gFilm[pixel] = f;
}
