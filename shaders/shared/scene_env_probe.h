// scene_env_probe.comp: evaluates the environment functions of lib/scene.glsl (radiance and
// pdf of a direction, a sample from two random numbers) for a list of queries. For debugging
// light sampling and to test the GLSL against src/scene/surface.h.
#ifndef OSR_SHARED_SCENE_ENV_PROBE_H
#define OSR_SHARED_SCENE_ENV_PROBE_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(scene_env_probe)
OSR_CONST(uint, kWorkgroupSize, 64);
OSR_CONST(uint, kBindingQueries, 0);
OSR_CONST(uint, kBindingResults, 1);
OSR_CONST(uint, kBindingScene, 2);  // OSR_SCENE_BINDING: scene buffers follow

struct Query {
  vec3 direction;  // unit, for environmentRadiance / environmentPdf
  float _pad0;
  vec2 u;          // for sampleEnvironment
  vec2 _pad1;
};

struct Result {
  vec3 radiance;  // environmentRadiance(direction)
  float pdf;      // environmentPdf(direction)
  vec3 sampledDirection;
  float sampledPdf;
  vec3 sampledRadiance;
  float _pad0;
};

struct Push {
  uint count;
};
OSR_NAMESPACE_END
#endif
