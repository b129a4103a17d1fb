// How much a neighbour counts in the two convergence passes' window sums (denoise_bias.comp,
// denoise_converge.comp; shared/denoise.h, "Convergence").
#ifndef OSR_LIB_CONVERGE_WEIGHT_GLSL
#define OSR_LIB_CONVERGE_WEIGHT_GLSL
#include "shared/denoise.h"

// Neighbour q of pixel p, from their film normals: 1 on p's own face, kConvergeWeightFloor
// across an edge; a NaN normal gets the floor.
float convergeWeight(vec3 np, vec3 nq) {
  const vec3 d = nq - np;
  const float d2 = dot(d, d);  // at most 4 between normals of length <= 1
  return d2 <= 4.0 ? max(exp(-kConvergeNormalSigma * d2), kConvergeWeightFloor) : kConvergeWeightFloor;
}

#endif
