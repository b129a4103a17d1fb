#version 460
// scene_probe: result[i] = surfaceAt(query[i]) and osrAlphaCutout(query[i]) for i < count.
// Inputs: queries (triangle, barycentrics), the scene buffers. Output: one Result per query.
// One invocation per query, no shared memory.
#extension GL_GOOGLE_include_directive : require
#include "shared/scene_probe.h"
#define OSR_SCENE_BINDING kBindingScene
#include "lib/scene.glsl"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kBindingQueries) readonly buffer Queries { Query gQueries[]; };
layout(std430, binding = kBindingResults) writeonly buffer Results { Result gResults[]; };
layout(push_constant) uniform PushBlock { Push gPush; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= gPush.count) return;
  Query q = gQueries[i];
  vec2 b = vec2(q.b1, q.b2);
  SurfaceSample s = surfaceAt(q.triangle, b);
  Result r;
  r.position = s.position;
  r.material = s.material;
  r.geometricNormal = s.geometricNormal;
  // A fixed ray for blended materials' hash; scene::alphaCutout hashes the same one.
  r.alphaCutout = osrAlphaCutout(q.triangle, b, kProbeRayOrigin, kProbeRayInvDir) ? 1u : 0u;
  r.shadingNormal = s.shadingNormal;
  r.alpha = s.m.alpha;
  r.baseColor = s.m.baseColor;
  r.metallic = s.m.metallic;
  r.emission = s.m.emission;
  r.roughness = s.m.roughness;
  r.specularColor = s.m.specularColor;
  r.specular = s.m.specular;
  r.uv = s.uv.xy;
  r.ior = s.m.ior;
  r.transmission = s.m.transmission;
  r.doubleSided = s.m.doubleSided ? 1u : 0u;
  r._pad0 = 0u;
  r._pad1 = 0u;
  r._pad2 = 0u;
  gResults[i] = r;
}
