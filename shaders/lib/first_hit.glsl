// The first-hit record: what the albedo, normal and depth layers of the film (shared/film.h)
// hold for one sample, written the same way by every integrator.
#ifndef OSR_LIB_FIRST_HIT_GLSL
#define OSR_LIB_FIRST_HIT_GLSL
#include "shared/film.h"

// The denoisers' guides. Path tracing and OSR record the first surface that is not a mirror
// (lib/bsdf.glsl bsdfGuideMirror), seen through the mirrors in front of it, at most
// kGuideChainSurfaces surfaces deep (pt_trace.comp CameraPath, osr_gbuffer.comp); preview
// the first.
struct FirstHit {
  vec3 albedo;  // the recorded surface's denoiseAlbedo (lib/bsdf.glsl; times the mirrors');
                // preview: its base colour
  vec3 normal;  // its shading normal, facing the camera ray (world)
  float depth;  // its (through mirrors: its virtual image's) distance along the view axis
  bool hit;
  float light;  // 1 when the camera ray saw light directly (an emitter or the environment,
                // or in path tracing one seen in a mirror: osr_gbuffer.comp says why not OSR)
};
const uint kGuideChainSurfaces = 4u;  // surfaces the record looks at, at most (3 mirrors)

FirstHit noFirstHit() {
  FirstHit h;
  h.albedo = vec3(0.0);
  h.normal = vec3(0.0);
  h.depth = 0.0;
  h.hit = false;
  h.light = 0.0;
  return h;
}

// The record while it looks through mirrors, built surface by surface along the camera ray's
// chain the same way by path tracing and OSR.
struct GuideChain {
  bool open;         // the record still looks past the last surface recorded (a mirror)
  vec3 tint;         // the product of the mirrors' albedos so far
  float pathLength;  // the chain's length to the last surface recorded
  float viewCos;     // view-axis depth per unit length along the camera ray
};

GuideChain guideChainStart() {
  GuideChain g;
  g.open = true;
  g.tint = vec3(1.0);
  g.pathLength = 0.0;
  g.viewCos = 1.0;
  return g;
}

// Records the chain's surface `index` (0: the camera ray's first hit), `segment` beyond the
// last one, at view-axis distance `viewDepth` from the camera: the record takes its albedo
// tinted by the mirrors before it and the depth of its virtual image. The record looks on
// past it when it is a mirror (`lookPast`) and the chain is not yet kGuideChainSurfaces deep.
void guideChainRecord(inout GuideChain g, inout FirstHit first, uint index, float segment, float viewDepth,
                      vec3 albedo, vec3 normal, bool lookPast) {
  g.pathLength += segment;
  if (index == 0u) g.viewCos = viewDepth / max(g.pathLength, 1e-30);
  first.hit = true;
  first.albedo = g.tint * albedo;
  first.normal = normal;
  first.depth = g.viewCos * g.pathLength;
  g.tint *= albedo;
  g.open = lookPast && index + 1u < kGuideChainSurfaces;
}

// 1 when a camera ray's first hit (or miss) gives it light: what the denoisers keep out of
// their neighbours (shared/denoise.h).
float lightSeen(vec3 emitted) { return any(greaterThan(emitted, vec3(0.0))) ? 1.0 : 0.0; }

// Adds one sample's first-hit record to the pixel's running sums (depth.y counts hits).
void filmAddFirstHit(inout FilmPixel f, FirstHit h) {
  f.albedo += vec4(h.albedo, h.light);
  f.normal.rgb += h.normal;
  f.depth += h.hit ? vec4(h.depth, 1.0, 0.0, 0.0) : vec4(0.0);
}

#endif
