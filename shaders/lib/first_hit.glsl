// The first-hit record: what the albedo, normal and depth layers of the film (shared/film.h)
// hold for one sample, written the same way by every integrator.
#ifndef OSR_LIB_FIRST_HIT_GLSL
#define OSR_LIB_FIRST_HIT_GLSL
#include "shared/film.h"

struct FirstHit {
  vec3 albedo;  // base colour of the first surface
  vec3 normal;  // its shading normal, facing the camera ray (world)
  float depth;  // its distance along the camera's view axis
  bool hit;
};

FirstHit noFirstHit() {
  FirstHit h;
  h.albedo = vec3(0.0);
  h.normal = vec3(0.0);
  h.depth = 0.0;
  h.hit = false;
  return h;
}

// Adds one sample's first-hit record to the pixel's running sums (depth.y counts hits).
void filmAddFirstHit(inout FilmPixel f, FirstHit h) {
  f.albedo.rgb += h.albedo;
  f.normal.rgb += h.normal;
  f.depth += h.hit ? vec4(h.depth, 1.0, 0.0, 0.0) : vec4(0.0);
}

#endif
