#version 460
// osr_resolve: the film (shared/film.h, one sample's worth: combined.w = 1) from OSR's
// running sums: direct averaged over passes; indirect = (sum w_k (maps + path-traced lobes)
// + residualBlend x sum w_k residual) / sum w_k; first-hit layers averaged over passes.
// residualBlend (host: n / (n + n0) for n residual samples) keeps the first images free of
// the residual's noise and tends to 1, where the estimate is unbiased.
// In: AccumPixel. Out: FilmPixel.
#extension GL_GOOGLE_include_directive : require
#include "shared/osr.h"
#include "shared/film.h"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(std430, binding = kOsrBindingAccum) readonly buffer OsrAccum { AccumPixel gAccum[]; };
layout(std430, binding = kOsrBindingFilm) writeonly buffer OsrFilm { FilmPixel gFilm[]; };
layout(push_constant) uniform OsrPushBlock { OsrPush gPush; };

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  AccumPixel a = gAccum[local];
  float passes = max(a.direct.w, 1.0);
  vec3 direct = a.direct.rgb / passes;
  vec3 indirect = a.indirect.w > 0.0
                      ? (a.indirect.rgb + gPush.residualBlend * a.residual.rgb) / a.indirect.w
                      : vec3(0.0);
  FilmPixel f;
  f.combined = vec4(direct + indirect, 1.0);
  f.direct = vec4(direct, 0.0);
  f.indirect = vec4(indirect, 0.0);
  f.albedo = vec4(a.albedo.rgb / passes, 0.0);
  f.normal = vec4(a.normal.rgb / passes, 0.0);
  f.depth = a.depth;
  gFilm[local] = f;
}
