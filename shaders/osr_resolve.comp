#version 460
// osr_resolve: the film (shared/film.h, one sample's worth: combined.w = 1) from OSR's
// running sums: direct averaged over passes weighted by their light samples; indirect =
// (sum w_k (maps + path-traced lobes) + beta x sum w_k residual) / sum w_k; first-hit layers
// averaged over passes.
// beta (docs/osr.md "Blending the residual in"): with residualBlend >= 0 (a fixed ramp the
// host computes), that value; with residualBlend < 0, per pixel and channel, the shrinkage of
// shared/osr.h residualShrinkBlend over the kShrinkRadius neighbourhood: the residual's
// noise-free maps early, the residual where the maps are measurably wrong, 1 in the limit.
// In: AccumPixel. Out: FilmPixel.
#extension GL_GOOGLE_include_directive : require
#include "shared/osr.h"
#include "shared/film.h"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(std430, binding = kOsrBindingAccum) readonly buffer OsrAccum { AccumPixel gAccum[]; };
layout(std430, binding = kOsrBindingFilm) writeonly buffer OsrFilm { FilmPixel gFilm[]; };
layout(std430, binding = kOsrBindingFrame) readonly buffer OsrFrame { CameraFrame gFrame; };
layout(push_constant) uniform OsrPushBlock { ResolvePush gPush; };

// Half-width of the square neighbourhood whose statistics set a pixel's blend: one pixel's
// own variance estimate is too noisy after a few passes; 9 x 9 was the smallest size past
// which the error stopped falling (docs/osr.md "Blending the residual in").
const int kShrinkRadius = 4;

vec3 shrinkBlend(uint local, uint pixel, AccumPixel centre) {
  int width = int(gFrame.width);
  int x = int(pixel % gFrame.width);
  vec3 sumVar = vec3(0.0), sumSq = vec3(0.0);
  // Neighbours inside this dispatch's pixel window (windows split only very large films).
  for (int dy = -kShrinkRadius; dy <= kShrinkRadius; ++dy) {
    for (int dx = -kShrinkRadius; dx <= kShrinkRadius; ++dx) {
      int q = int(local) + dy * width + dx;
      if (x + dx < 0 || x + dx >= width || q < 0 || q >= int(gPush.pixelCount)) continue;
      // Only the three fields the blend needs, not whole AccumPixels.
      float weightSum = gAccum[q].indirect.w;
      vec4 residual = gAccum[q].residual, residualSq = gAccum[q].residualSq;
      if (!residualVarianceKnown(residualSq, weightSum)) continue;
      vec3 mean = residual.rgb / weightSum;
      sumVar += residualVarianceOfMean(residual, residualSq, weightSum);
      sumSq += mean * mean;
    }
  }
  return residualShrinkBlend(sumVar, sumSq, residualPasses(centre.residualSq, centre.indirect.w),
                             gPush.residualNoiseWeight);
}

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  AccumPixel a = gAccum[local];
  float passes = max(a.albedo.w, 1.0);
  vec3 direct = a.direct.w > 0.0 ? a.direct.rgb / a.direct.w : vec3(0.0);
  // The blend weighs the residual of the indirect light: a pixel without any (a first pass
  // stopped before its band) needs no neighbourhood, whose 81 reads cost seconds at 4K.
  vec3 blend = gPush.residualBlend >= 0.0 ? vec3(gPush.residualBlend)
             : a.indirect.w > 0.0       ? shrinkBlend(local, pixel, a)
                                        : vec3(0.0);
  vec3 indirect = a.indirect.w > 0.0 ? (a.indirect.rgb + blend * a.residual.rgb) / a.indirect.w
                                     : vec3(0.0);
  FilmPixel f;
  f.combined = vec4(direct + indirect, 1.0);
  f.direct = vec4(direct, 0.0);
  f.indirect = vec4(indirect, 0.0);
  f.albedo = vec4(a.albedo.rgb / passes, a.depth.z / passes);
  f.normal = vec4(a.normal.rgb / passes, 0.0);
  // The second moment of one sample's worth: the estimate squared plus its variance, that of
  // the blended residual's mean, of the direct light's mean, of the composite's mean over map
  // passes, of the fully path-traced part's mean and of the lights seen in mirrors (film.h:
  // what the denoisers' variance comes from). The maps' bias is not in it.
  const vec3 lumWeights = vec3(0.2126, 0.7152, 0.0722);
  const float lum = dot(f.combined.rgb, lumWeights);
  const vec3 residualVar = a.indirect.w > 0.0
      ? blend * blend * residualVarianceOfMean(a.residual, a.residualSq, a.indirect.w) : vec3(0.0);
  // Over the samples, without the emission seen (osr_gbuffer's, which is not sampled noise).
  const float directSamples = a.direct.w;
  const float directVar = directSamples > 1.5
      ? max(a.normal.w - a.depth.w * a.depth.w / directSamples, 0.0) / (directSamples * (directSamples - 1.0))
      : 0.0;
  f.depth = vec4(a.depth.xy,
                 lum * lum + dot(residualVar, lumWeights) + directVar +
                     varianceOfWeightedMean(a.compositeSq) + varianceOfWeightedMean(a.tracedSq) +
                     varianceOfWeightedMean(a.mirroredSq),
                 0.0);
  gFilm[local] = f;
}
