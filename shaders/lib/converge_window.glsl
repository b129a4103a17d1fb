// What the two convergence passes (denoise_bias.comp, denoise_converge.comp; shared/denoise.h,
// "Convergence") share in their window sums: how much a neighbour counts, and how many of the
// film's standard deviations a gap must exceed to count as the denoiser's bias.
#ifndef OSR_LIB_CONVERGE_WINDOW_GLSL
#define OSR_LIB_CONVERGE_WINDOW_GLSL
#include "shared/denoise.h"

// Neighbour q of pixel p, from their film normals: 1 on p's own face, kConvergeWeightFloor
// across an edge; a NaN normal gets the floor.
float convergeWeight(vec3 np, vec3 nq) {
  const vec3 d = nq - np;
  const float d2 = dot(d, d);  // at most 4 between normals of length <= 1
  return d2 <= 4.0 ? max(exp(-kConvergeNormalSigma * d2), kConvergeWeightFloor) : kConvergeWeightFloor;
}

// k = 1 + scale x the window's relative standard error: the root of its weighted mean variance
// (noise = sum(w v)) over its weighted mean denoised level (level = sum(w l_d)), weights =
// sum(w). Where few paths carry most of the light, a gap of several standard deviations of a
// heavy-tailed variance estimate is still noise.
float convergeNoiseFactor(float scale, float noise, float level, float weights) {
  return 1.0 + scale * sqrt(noise / weights) / max(level / weights, 1e-4);
}

#endif
