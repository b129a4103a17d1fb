// Hemisphere maps (DESIGN.md "Hemisphere maps"): the tangent frame of a map and the
// cosine-weighted concentric mapping between the unit square and the hemisphere around +z,
// written once for C++ (osr::gpu::hemi) and GLSL. Every texel of a square map covers the same
// projected solid angle, so irradiance is pi x the texel mean.
//   square (u, v) in [0, 1)^2 -> Shirley-Chiu concentric disk point d -> (d, sqrt(1 - |d|^2))
// The mapping commutes with the 8 symmetries of the square: rotating the square by 90 degrees
// rotates the direction about z by 90 degrees, mirroring u mirrors x. Texel (x, y) of an
// N x N map is element y * N + x and covers u in [x, x + 1) / N, v in [y, y + 1) / N.
// C++ twin tested against the GPU and for the round trip by tests/osr/test_hemisphere.cpp.
#ifndef OSR_SHARED_HEMISPHERE_H
#define OSR_SHARED_HEMISPHERE_H
#include "shared/types.h"

#ifdef __cplusplus
#include <cmath>
#define OSR_HEMI_FN inline
#define OSR_HEMI_ATAN2(y, x) std::atan2(y, x)
#else
#define OSR_HEMI_FN
#define OSR_HEMI_ATAN2(y, x) atan(y, x)
#endif

OSR_NAMESPACE_BEGIN(hemi)
#ifdef __cplusplus
using glm::abs;
using glm::max;
using glm::min;
using std::sqrt;
using std::cos;
using std::sin;
#endif

OSR_CONST(uint, kMapSize, 32u);  // texels per side
OSR_CONST(uint, kMapTexels, 1024u);
OSR_CONST(float, kHemiPi, 3.14159265358979323846f);

// osr_hemisphere_probe.comp (tests): case i reads probe[i].square and probe[i].direction and
// writes the mapping of each and the frame of probe[i].normal.
OSR_CONST(uint, kHemiProbeWorkgroupSize, 64u);
OSR_CONST(uint, kHemiProbeBindingCases, 0u);
struct HemiProbeCase {
  vec4 square;     // in: xy in [0, 1)^2;  out (zw): hemiDirectionToSquare(hemiSquareToDirection)
  vec4 direction;  // in: xyz unit, z >= 0; out: w unused
  vec4 normal;     // in: xyz unit
  vec4 toDirection;  // out: hemiSquareToDirection(square.xy)
  vec4 toSquare;     // out: xy = hemiDirectionToSquare(direction.xyz)
  vec4 frameT;       // out: hemiFrame(normal) columns
  vec4 frameB;
};

// Orthonormal frame with z = n, from the normal alone (Duff et al. 2017), as columns
// (tangent, bitangent, normal): world = frame * local, local = transpose(frame) * world.
OSR_HEMI_FN mat3 hemiFrame(vec3 n) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float c = n.x * n.y * a;
  return mat3(vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x), vec3(c, s + n.y * n.y * a, -n.y),
              n);
}

// Unit square -> unit disk (Shirley & Chiu 1997, as pbrt's SampleUniformDiskConcentric).
OSR_HEMI_FN vec2 hemiSquareToDisk(vec2 u) {
  vec2 o = 2.0f * u - 1.0f;
  if (o.x == 0.0f && o.y == 0.0f) return vec2(0.0f);
  float r, theta;
  if (abs(o.x) > abs(o.y)) {
    r = o.x;
    theta = (kHemiPi / 4.0f) * (o.y / o.x);
  } else {
    r = o.y;
    theta = (kHemiPi / 2.0f) - (kHemiPi / 4.0f) * (o.x / o.y);
  }
  return r * vec2(cos(theta), sin(theta));
}

// Unit disk -> unit square, the inverse of hemiSquareToDisk.
OSR_HEMI_FN vec2 hemiDiskToSquare(vec2 d) {
  float len = sqrt(d.x * d.x + d.y * d.y);
  if (len == 0.0f) return vec2(0.5f);
  vec2 o;
  if (abs(d.x) >= abs(d.y)) {
    float r = d.x >= 0.0f ? len : -len;
    float theta = OSR_HEMI_ATAN2(d.y / r, d.x / r);  // in [-pi/4, pi/4]
    o = vec2(r, r * theta * (4.0f / kHemiPi));
  } else {
    float r = d.y >= 0.0f ? len : -len;
    float theta = OSR_HEMI_ATAN2(d.y / r, d.x / r);  // in [pi/4, 3pi/4]
    o = vec2(r * (kHemiPi / 2.0f - theta) * (4.0f / kHemiPi), r);
  }
  return min(max(0.5f * o + 0.5f, vec2(0.0f)), vec2(0.99999994f));
}

// Square -> direction in the map's frame (z >= 0), cosine-weighted: pdf = z / pi.
OSR_HEMI_FN vec3 hemiSquareToDirection(vec2 u) {
  vec2 d = hemiSquareToDisk(u);
  return vec3(d.x, d.y, sqrt(max(0.0f, 1.0f - d.x * d.x - d.y * d.y)));
}

// Direction in the map's frame (z >= 0; z < 0 is projected onto the rim) -> square.
OSR_HEMI_FN vec2 hemiDirectionToSquare(vec3 w) {
  return hemiDiskToSquare(vec2(w.x, w.y));
}

OSR_NAMESPACE_END
#endif
