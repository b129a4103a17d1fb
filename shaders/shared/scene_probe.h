// scene_probe.comp: evaluates lib/scene.glsl at a list of hit records (triangle, barycentrics),
// writing the surface a shading pass would see. Used for G-buffer debugging and to test the
// GLSL scene accessors against their C++ twins (src/scene/surface.h).
#ifndef OSR_SHARED_SCENE_PROBE_H
#define OSR_SHARED_SCENE_PROBE_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(scene_probe)
OSR_CONST(uint, kWorkgroupSize, 64);
OSR_CONST(uint, kBindingQueries, 0);
OSR_CONST(uint, kBindingResults, 1);
OSR_CONST(uint, kBindingScene, 2);  // OSR_SCENE_BINDING: scene buffers follow
// The ray whose hash decides blended hits' alphaCutout in the probe.
#ifdef __cplusplus
inline const vec3 kProbeRayOrigin{0.25f, 0.5f, 0.75f};
inline const vec3 kProbeRayInvDir{1.0f, -2.0f, 4.0f};
#else
const vec3 kProbeRayOrigin = vec3(0.25, 0.5, 0.75);
const vec3 kProbeRayInvDir = vec3(1.0, -2.0, 4.0);
#endif

struct Query {
  uint triangle;
  float b1;  // barycentric weight of v1
  float b2;  // barycentric weight of v2
  uint _pad0;
};

struct Result {
  vec3 position;
  uint material;
  vec3 geometricNormal;
  uint alphaCutout;  // osrAlphaCutout(): 1 if the hit is in a hole
  vec3 shadingNormal;
  float alpha;
  vec3 baseColor;  // linear, texture x factor
  float metallic;
  vec3 emission;
  float roughness;
  vec3 specularColor;
  float specular;
  vec2 uv;
  float ior;
  float transmission;
  uint doubleSided;
  uint _pad0;
  uint _pad1;
  uint _pad2;
};

struct Push {
  uint count;
};
OSR_NAMESPACE_END
#endif
