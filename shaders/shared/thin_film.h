// The thin-film Fresnel of KHR_materials_iridescence, written once for GLSL (lib/bsdf.glsl)
// and C++ (tests/pt/test_bsdf_probe.cpp checks its range and limits on the host).
// Belcour and Barla 2017, "A Practical Extension to Microfacet Theory for the Modeling of
// Varying Iridescence", in the approximate form the extension gives: Schlick reflectances at
// both interfaces (no polarisation), phase shifts of 0 or pi, the Airy series' first two
// orders integrated against Gaussian fits of the XYZ colour matching functions, then to
// linear Rec. 709. Floats carry an f suffix so that glm sees no double.
#ifndef OSR_SHARED_THIN_FILM_H
#define OSR_SHARED_THIN_FILM_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(thin_film)

#ifdef __cplusplus
#define OSR_THIN_FILM_FN inline
using glm::clamp;
using glm::cos;
using glm::exp;
using glm::max;
using glm::min;
using glm::mix;
using glm::smoothstep;
using glm::sqrt;
#else
#define OSR_THIN_FILM_FN
#endif

OSR_CONST(float, kThinFilmPi, 3.14159265358979f);

// Normal-incidence reflectance of the interface from ior nI into ior nT.
OSR_THIN_FILM_FN float thinFilmF0(float nT, float nI) {
  float r = (nT - nI) / (nT + nI);
  return r * r;
}

OSR_THIN_FILM_FN vec3 thinFilmSchlick(vec3 f0, float c) {
  float m = clamp(1.0f - c, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (vec3(1.0f) - f0) * (m2 * m2 * m);
}

// The colour matching functions' response to an optical path difference opd (nm) with phase
// shift `shift` per channel: the Fourier transform of the Gaussian fits, normalised so that
// opd 0 gives XYZ (1, 1, 1), in linear Rec. 709.
OSR_THIN_FILM_FN vec3 thinFilmSensitivity(float opd, vec3 shift) {
  float phase = 2.0f * kThinFilmPi * opd * 1.0e-9f;
  vec3 val = vec3(5.4856e-13f, 4.4201e-13f, 5.2481e-13f);
  vec3 pos = vec3(1.6810e+06f, 1.7953e+06f, 2.2084e+06f);
  vec3 var = vec3(4.3278e+09f, 9.3046e+09f, 6.6121e+09f);
  vec3 xyz = val * sqrt(2.0f * kThinFilmPi * var) * cos(pos * phase + shift) *
             exp(-(phase * phase) * var);
  xyz.x += 9.7470e-14f * sqrt(2.0f * kThinFilmPi * 4.5282e+09f) *
           cos(2.2399e+06f * phase + shift.x) * exp(-4.5282e+09f * phase * phase);
  xyz = xyz / 1.0685e-7f;
  // XYZ to linear Rec. 709, column-major.
  mat3 rgbFromXyz = mat3(3.2404542f, -0.9692660f, 0.0556434f, -1.5371385f, 1.8760108f, -0.2040259f,
                         -0.4985314f, 0.0415560f, 1.0572252f);
  return rgbFromXyz * xyz;
}

// Reflectance of a film of ior filmIor and thickness thicknessNm (> 0) between a medium of
// ior outsideIor and a base of normal-incidence reflectance baseF0, at cosine cosTheta1 from
// the outside. The extension's series leaves [0, 1] (up to 1.26 and down to -0.19 over the
// iors 1-2.5 and thicknesses 0-1200 nm): clamped per channel so that the layer never
// reflects more than arrives (the extension clamps at 0 only).
OSR_THIN_FILM_FN vec3 thinFilmFresnel(float outsideIor, float filmIor, float thicknessNm,
                                      vec3 baseF0, float cosTheta1) {
  cosTheta1 = clamp(cosTheta1, 0.0f, 1.0f);
  // A film thinner than 0.03 nm fades into the outside medium (the extension's rule).
  float n2 = mix(outsideIor, filmIor, smoothstep(0.0f, 0.03f, thicknessNm));
  float sin2Theta2 = (outsideIor / n2) * (outsideIor / n2) * (1.0f - cosTheta1 * cosTheta1);
  if (sin2Theta2 >= 1.0f) return vec3(1.0f);  // total internal reflection into the film
  float cosTheta2 = sqrt(1.0f - sin2Theta2);
  // First interface (outside -> film), its reflectance the same both ways.
  float r12 = thinFilmSchlick(vec3(thinFilmF0(n2, outsideIor)), cosTheta1).x;
  float t121 = 1.0f - r12;
  float phi12 = n2 < outsideIor ? kThinFilmPi : 0.0f;
  float phi21 = kThinFilmPi - phi12;
  // Second interface (film -> base): the base's ior from its F0, as if it were a dielectric
  // (a metal's extinction cannot be recovered from F0; the extension takes it as 0).
  vec3 sqrtF0 = sqrt(clamp(baseF0, vec3(0.0f), vec3(0.9999f)));
  vec3 baseIor = (vec3(1.0f) + sqrtF0) / (vec3(1.0f) - sqrtF0);
  vec3 r1 = (baseIor - vec3(n2)) / (baseIor + vec3(n2));
  vec3 r23 = thinFilmSchlick(r1 * r1, cosTheta2);
  vec3 phi23 = vec3(baseIor.x < n2 ? kThinFilmPi : 0.0f, baseIor.y < n2 ? kThinFilmPi : 0.0f,
                    baseIor.z < n2 ? kThinFilmPi : 0.0f);
  float opd = 2.0f * n2 * thicknessNm * cosTheta2;
  vec3 phi = vec3(phi21) + phi23;
  // The Airy series: the incoherent sum (order 0), then two orders of interference.
  vec3 r123 = clamp(r12 * r23, vec3(1e-5f), vec3(0.9999f));
  vec3 sqrtR123 = sqrt(r123);
  vec3 rs = t121 * t121 * r23 / (vec3(1.0f) - r123);
  vec3 reflectance = vec3(r12) + rs;
  vec3 cm = rs - vec3(t121);
  for (int m = 1; m <= 2; ++m) {
    cm = cm * sqrtR123;
    reflectance += cm * 2.0f * thinFilmSensitivity(float(m) * opd, float(m) * phi);
  }
  return clamp(reflectance, vec3(0.0f), vec3(1.0f));
}

#undef OSR_THIN_FILM_FN
OSR_NAMESPACE_END
#endif
