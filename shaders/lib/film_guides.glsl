// What the passes over a film's layers read their guides through (the a-trous filter's,
// temporal reuse's): the albedo colour is divided by, and the pixel's mean shading direction.
#ifndef OSR_LIB_FILM_GUIDES_GLSL
#define OSR_LIB_FILM_GUIDES_GLSL
#include "lib/sampling.glsl"  // luminance

// What colour is divided by: the albedo, or 1 where the first hit has (almost) none (misses,
// black surfaces), so that their light is filtered or blended as it is.
vec3 demodulator(vec3 albedo) {
  return luminance(albedo) < 1e-3 ? vec3(1.0) : max(albedo, vec3(1e-3));
}

// A film normal (the mean over a pixel's samples, shorter than 1 where the pixel straddles an
// edge) as a unit direction; 0 where there is none.
vec3 unitNormal(vec3 n) {
  const float len2 = dot(n, n);
  return len2 > 1e-12 ? n * inversesqrt(len2) : vec3(0.0);
}

// The logarithm of the normal factor of an edge-aware filter's tap q for pixel p, from their
// film normals: sigma log(max(cos, cosMin)) between their unit directions; or, where p's mean
// normal is shorter than straddleLength (its samples saw two faces: it straddles an edge),
// -straddleSigma |n_p - n_q|^2 on the means, so that pixels along the edge with about the same
// mix of the two faces agree and the faces themselves do not (tools/image_unet.py
// STRADDLE_LENGTH). With the unit directions such a pixel agreed with nobody and kept its noise.
float normalLogFactor(vec3 np, vec3 nq, float sigma, float cosMin, float straddleLength, float straddleSigma) {
  if (dot(np, np) < straddleLength * straddleLength) {
    const vec3 d = np - nq;
    return -straddleSigma * dot(d, d);
  }
  return sigma * log(max(dot(unitNormal(np), unitNormal(nq)), cosMin));
}

#endif
