// CPU twin of the watertight ray-triangle test in shaders/lib/bvh_traverse.glsl (Woop, Benthin,
// Wald 2013), for brute-force references in tests and benchmark verification.
#pragma once
#include <glm/glm.hpp>
#include <utility>

namespace osr::bvh {

struct ShearedRay {
  glm::vec3 origin;
  int kx, ky, kz;
  glm::vec3 shear;
  ShearedRay(const glm::vec3& o, const glm::vec3& dir) : origin(o) {
    glm::vec3 a = glm::abs(dir);
    kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (dir[kz] < 0.0f) std::swap(kx, ky);
    shear = glm::vec3(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0f / dir[kz]);
  }
};

// True on a hit with tMin < t < tFar; bary = weights of v1, v2.
inline bool intersectTriangle(const ShearedRay& r, const glm::vec3& v0, const glm::vec3& v1,
                              const glm::vec3& v2, float tMin, float tFar, float& t,
                              glm::vec2& bary) {
  glm::vec3 A = v0 - r.origin, B = v1 - r.origin, C = v2 - r.origin;
  // Plain indexed loads: glm's operator[] is a switch per access, several times slower here.
  const float* a = &A.x;
  const float* b = &B.x;
  const float* c = &C.x;
  float ax = a[r.kx] - r.shear.x * a[r.kz];
  float ay = a[r.ky] - r.shear.y * a[r.kz];
  float bx = b[r.kx] - r.shear.x * b[r.kz];
  float by = b[r.ky] - r.shear.y * b[r.kz];
  float cx = c[r.kx] - r.shear.x * c[r.kz];
  float cy = c[r.ky] - r.shear.y * c[r.kz];
  float U = cx * by - cy * bx;
  float V = ax * cy - ay * cx;
  float W = bx * ay - by * ax;
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  float det = U + V + W;
  if (det == 0.0f) return false;
  float T = U * (r.shear.z * a[r.kz]) + V * (r.shear.z * b[r.kz]) + W * (r.shear.z * c[r.kz]);
  float rcpDet = 1.0f / det;
  t = T * rcpDet;
  if (!(t > tMin && t < tFar)) return false;
  bary = glm::vec2(V, W) * rcpDet;
  return true;
}

}  // namespace osr::bvh
