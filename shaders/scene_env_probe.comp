#version 460
// scene_env_probe: for i < count, result[i] = environment radiance and pdf of query[i].direction,
// and sampleEnvironment(query[i].u). Inputs: queries, the scene buffers (environment and its
// CDFs). One invocation per query.
#extension GL_GOOGLE_include_directive : require
#include "shared/scene_env_probe.h"
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
  Result r;
  r.radiance = environmentRadiance(q.direction);
  r.pdf = environmentPdf(q.direction);
  r.sampledDirection = sampleEnvironment(q.u, r.sampledPdf, r.sampledRadiance);
  r._pad0 = 0.0;
  gResults[i] = r;
}
