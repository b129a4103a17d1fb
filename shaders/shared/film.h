// The film every integrator resolves into (src/render/film.h): per-pixel running sums the
// host divides by the sample count.
#ifndef OSR_SHARED_FILM_H
#define OSR_SHARED_FILM_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(film)

// Running sums per pixel; the host divides by the sample count (combined.w).
// direct: emission met before or at the first surface that is not near-specular (mirror-like
// metal, smooth glass) and light reaching that surface in one hop; indirect: the rest
// (combined = direct + indirect; docs/pathtracer.md "Film layers"). albedo, normal (world, facing the camera) and depth
// (distance along the camera's view axis, x = sum, y = number of samples that hit) are of the
// first surface (path tracing: the first that is not a mirror, lib/first_hit.glsl). depth.z: the sum of the squared luminance of the combined samples, the second
// moment the denoisers' variance comes from (OSR's resolve, one sample's worth, stores its
// estimate's luminance squared plus the estimate's variance; render/film.cpp). albedo.w: the
// number of samples whose camera ray saw light directly (an emitter or the environment), which
// the denoisers keep out of their neighbours' averages.
struct FilmPixel {
  vec4 combined;
  vec4 direct;
  vec4 indirect;
  vec4 albedo;
  vec4 normal;
  vec4 depth;
};

OSR_NAMESPACE_END
#endif
