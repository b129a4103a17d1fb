// Sampling helpers shared by every integrator: orthonormal frames from a normal, warps from
// the unit square and their densities.
#ifndef OSR_LIB_SAMPLING_GLSL
#define OSR_LIB_SAMPLING_GLSL
#include "shared/hemisphere.h"

const float kPi = 3.14159265358979323846;
const float kInvPi = 0.31830988618379067154;

// Orthonormal basis with z = n, from the normal alone (shared/hemisphere.h hemiFrame, Duff et
// al. 2017), so every pass, and the hemisphere maps, derive the same tangent frame.
void frameFromNormal(vec3 n, out vec3 t, out vec3 b) {
  mat3 f = hemiFrame(n);
  t = f[0];
  b = f[1];
}

vec3 toLocal(vec3 v, vec3 t, vec3 b, vec3 n) { return vec3(dot(v, t), dot(v, b), dot(v, n)); }
vec3 toWorld(vec3 v, vec3 t, vec3 b, vec3 n) { return v.x * t + v.y * b + v.z * n; }

// Shirley-Chiu concentric square -> disk map (uniform area).
vec2 concentricDisk(vec2 u) { return hemiSquareToDisk(u); }

// Cosine-weighted hemisphere around +z; pdf = z / pi. The same warp as the hemisphere maps'.
vec3 sampleCosineHemisphere(vec2 u) { return hemiSquareToDirection(u); }

// Uniform point on a triangle as barycentrics (b1, b2) (Heitz 2019 would avoid the sqrt;
// this is the classic warp, exact and cheap enough next to a ray cast).
vec2 sampleTriangle(vec2 u) {
  float s = sqrt(u.x);
  return vec2(1.0 - s, u.y * s);
}

// Uniform direction on the sphere; pdf = 1 / (4 pi).
vec3 sampleUniformSphere(vec2 u) {
  float z = 1.0 - 2.0 * u.x;
  float r = sqrt(max(0.0, 1.0 - z * z));
  float phi = 2.0 * kPi * u.y;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// Balance-free power heuristic (beta = 2) for two strategies.
float powerHeuristic(float pdfA, float pdfB) {
  float a = pdfA * pdfA;
  float b = pdfB * pdfB;
  return a + b > 0.0 ? a / (a + b) : 0.0;
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
float maxComponent(vec3 c) { return max(c.x, max(c.y, c.z)); }

#endif
