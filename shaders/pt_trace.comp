#version 460
// pt_trace: one sample per pixel for a range of pixels, added to the film's running sums.
// Inputs: Frame (camera, size, seed), the BVH, the scene; push: pixel range and sample index.
// Output: FilmPixel sums (shared/pt.h). A megakernel: each invocation follows its path to the
// end: on lavapipe a wavefront variant measured slower (src/pt/trace_pass.h,
// docs/pathtracer.md, "Tried and not kept").
//
// Path integrator (kIntegratorPath): camera rays drawn from the pixel filter (lib/camera.glsl:
// Cycles' Blackman-Harris, 2 px wide), then lib/path.glsl's bounce (next-event estimation with MIS, Russian roulette)
// until the path ends; light selection and pdfs are lib/lights.glsl's.
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
#define OSR_BSDF_LAYERS ((kSceneFeatures & kSceneFeatureLayers) != 0u)
#include "lib/bsdf.glsl"
#include "lib/ray_offset.glsl"
#include "lib/lights.glsl"
#include "lib/shading.glsl"
#include "lib/path.glsl"
#include "lib/camera.glsl"
#include "lib/first_hit.glsl"

layout(constant_id = kPtSpecIntegrator) const uint kIntegrator = kIntegratorPath;
layout(local_size_x = kPtWorkgroupSize) in;
// The film's window of this dispatch's pixels (src/render/film.h): gFilm[0] is pixelOffset.
layout(std430, binding = kPtBindingFilm) buffer Film { FilmPixel gFilm[]; };
layout(std430, binding = kPtBindingFrame) readonly buffer FrameBlock { CameraFrame gFrame; };
layout(push_constant) uniform PushBlock { Push gPush; };

// ---- Samples -----------------------------------------------------------------------------

struct Sample {
  vec3 direct;
  vec3 indirect;
  FirstHit first;
};

// Adds light that arrived after `bounces` surface interactions, not counting the
// near-specular surfaces the camera path met first, to the right film bucket: direct is
// emission and light reaching the first other surface in one hop, as in OSR, whose G-buffer
// follows mirrors and smooth glass (docs/pathtracer.md, "Film layers").
void addLight(inout Sample s, uint bounces, vec3 l) {
  if (bounces <= 1u) s.direct += l; else s.indirect += l;
}

// One camera sample in flight: the path and what it has gathered.
struct CameraPath {
  PathState path;
  Rng rng;
  uint pixel;
  uint sampleIndex;
  Sample s;
  // The first-hit record follows the path into mirrors (BounceResult.mirror), as Cycles'
  // denoising guides do: what the denoisers see there is the surface reflected, its albedo
  // tinted by the mirrors, its depth that of its virtual image (the path's length along the
  // camera ray: what temporal reuse reprojects is then where the reflection appears). A
  // texture in a mirror then has its edges in the albedo guide, and a lamp seen in a mirror
  // counts as light seen directly. Not through clear glass: its reflect-or-refract choice per
  // sample made the guides noisy, and the denoised interior 9001 worse at 55 spp
  // (docs/denoise.md, "Guides in mirrors").
  GuideChain guide;
  uint specularLead;  // near-specular surfaces met before any other (addLight)
};

// Stratified 2-D sample for dimension pair `pair` of this path's sample (see sobolOwen2).
vec2 stratified2(CameraPath c, uint pair) {
  return sobolOwen2(c.sampleIndex, pcgHash(c.pixel ^ pcgHash(gFrame.seed + pair * 0x9e3779b9u)));
}

// The three numbers of the light sample and the three of the BSDF sample: stratified over the
// pixel's samples at every surface, three dimension pairs per bounce (one holds both choices,
// one each the light point and the BSDF direction), each pair scrambled independently (padded
// 2-D sets, as Cycles pads its sequences).
void bounceRandoms(CameraPath c, out vec3 uLight, out vec3 uBsdf) {
  uint base = 1u + 3u * c.path.bounce;
  vec2 choice = stratified2(c, base);
  uLight = vec3(choice.x, stratified2(c, base + 1u));
  uBsdf = vec3(choice.y, stratified2(c, base + 2u));
}

// Starts sample `sampleIndex` of film pixel `pixel`: its random stream (keyed on the pixel's
// place in the whole image, lib/camera.glsl) and jittered camera ray.
CameraPath startPath(uint pixel, uint sampleIndex) {
  CameraPath c;
  c.pixel = imagePixelIndex(gFrame, pixel);
  c.rng = rngInit(c.pixel, sampleIndex, gFrame.seed);
  c.sampleIndex = sampleIndex;
  vec3 origin, dir;
  cameraRay(gFrame, pixel % gFrame.width, pixel / gFrame.width, stratified2(c, 0u), origin, dir);
  c.path = pathStart(origin, dir, vec3(1.0), 0.0, origin, 0u);
  c.s.direct = vec3(0.0);
  c.s.indirect = vec3(0.0);
  c.s.first = noFirstHit();
  c.guide = guideChainStart();
  c.specularLead = 0u;
  return c;
}

// One bounce of the camera path. Returns true when the path has ended.
bool pathStep(inout CameraPath c) {
  uint bounce = c.path.bounce;
  // Random numbers in the order the bounce consumes them (light, BSDF, roulette).
  vec3 uLight, uBsdf;
  bounceRandoms(c, uLight, uBsdf);
  float uRoulette = bounce >= 3u ? rngNext(c.rng) : 0.0;
  vec3 origin = c.path.origin;
  BounceResult r;
  bool ended = pathBounce(c.path, uLight, uBsdf, uRoulette, c.guide.open, r);
  if (c.guide.open) {
    if (bounce == 0u || lightSeen(r.emitted) > 0.0) c.s.first.light = lightSeen(r.emitted);
    if (r.hit) {
      guideChainRecord(c.guide, c.s.first, bounce, distance(origin, r.position),
                       cameraDepth(gFrame, r.position), r.albedo, r.normal, r.mirror && !ended);
    } else {
      c.guide.open = false;
    }
  }
  addLight(c.s, bounce - c.specularLead, r.emitted);
  addLight(c.s, bounce + 1u - c.specularLead, r.nee);
  // Every surface so far was near-specular exactly when they are all counted.
  if (c.specularLead == bounce && r.hit && r.nearSpecular) c.specularLead += 1u;
  return ended;
}

Sample tracePreview(vec3 origin, vec3 dir) {
  Sample s;
  s.direct = vec3(0.0);
  s.indirect = vec3(0.0);
  s.first = noFirstHit();
  Hit hit;
  if (!bvhClosestHit(origin, dir, 0.0, kInfinity, hit)) return s;
  SurfaceSample surf = surfaceAt(hit.triangle, hit.barycentrics);
  vec3 ns = surf.shadingNormal;
  if (dot(ns, dir) > 0.0) ns = -ns;
  s.first.hit = true;
  s.first.albedo = surf.m.baseColor;
  s.first.normal = ns;
  s.first.depth = cameraDepth(gFrame, surf.position);
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
  const float lum = finite ? dot(l, vec3(0.2126, 0.7152, 0.0722)) : 0.0;
  f.depth.z += lum * lum;
  f.direct.rgb += finite ? s.direct : vec3(0.0);
  f.indirect.rgb += finite ? s.indirect : vec3(0.0);
  f.normal.w += finite ? 0.0 : 1.0;
  filmAddFirstHit(f, s.first);
}

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  FilmPixel f = gFilm[local];
  if (kIntegrator == kIntegratorPreview) {
    for (uint i = 0u; i < gPush.sampleCount; ++i) {
      CameraPath c = startPath(pixel, gPush.sampleIndex + i);
      accumulate(f, tracePreview(c.path.origin, c.path.dir));
    }
  } else {
    // One flat loop over bounces of successive samples, so that a lane whose path ends starts
    // its next sample at once instead of idling until the longest path of its SIMD group ends
    // (path regeneration, Novak et al. 2010). Sample i uses the random stream of sample index
    // sampleIndex + i: the image does not depend on how samples are split into dispatches.
    uint i = 0u;
    CameraPath c = startPath(pixel, gPush.sampleIndex);
    while (true) {
      if (pathStep(c)) {
        accumulate(f, c.s);
        if (++i == gPush.sampleCount) break;
        c = startPath(pixel, gPush.sampleIndex + i);
      }
    }
  }
  gFilm[local] = f;
}
