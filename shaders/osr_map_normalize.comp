#version 460
// osr_map_normalize: the U-Net's input from one-shot maps, per DESIGN.md "Normalization"
// (shared/osr.h normalizeRadiance / normalizeDistance): radiance and distance log-scaled by the
// map's own means, normals as traced. An invocation or a workgroup per map of the chunk
// (lib/osr_map_group.glsl); also records the means that osr_map_denoise rescales the network's
// output to.
// In: one-shot maps [chunk][7][32][32]. Out: normalized [chunk][7][32][32], MapStats.
#extension GL_GOOGLE_include_directive : require
#include "shared/osr.h"

layout(local_size_x = kOsrWorkgroupSize) in;
#include "lib/osr_map_group.glsl"
layout(std430, binding = kOsrBindingMapOneShot) readonly buffer OsrOneShot { float gOneShot[]; };
layout(std430, binding = kOsrBindingMapStats) writeonly buffer OsrStats { MapStats gStats[]; };
layout(std430, binding = kOsrBindingNetIn) writeonly buffer OsrNetIn { float gNetIn[]; };
layout(push_constant) uniform OsrPushBlock { MapNormalizePush gPush; };

void main() {
  uint local = mapOfInvocation();
  if (local >= gPush.mapCount) return;
  uint base = local * kMapChannels * kMapTexels;
  uint t0 = firstMapTexel(), dt = mapTexelStep();
  vec4 sums = vec4(0.0);  // radiance rgb, distance
  for (uint t = t0; t < kMapTexels; t += dt)
    sums += vec4(gOneShot[base + t], gOneShot[base + kMapTexels + t],
                 gOneShot[base + 2u * kMapTexels + t], gOneShot[base + 6u * kMapTexels + t]);
  sums = mapSum(sums);
  vec3 mean = sums.rgb / float(kMapTexels);
  float meanAll = (mean.r + mean.g + mean.b) / 3.0;
  float meanDistance = sums.a / float(kMapTexels);
  if (t0 == 0u) {
    gStats[local].meanRadiance = vec4(mean, meanAll);
    gStats[local].meanDistance = vec4(meanDistance, 0.0, 0.0, 0.0);
  }
  for (uint t = t0; t < kMapTexels; t += dt) {
    for (uint c = 0u; c < 3u; ++c)
      gNetIn[base + c * kMapTexels + t] = normalizeRadiance(gOneShot[base + c * kMapTexels + t], meanAll);
    for (uint c = 3u; c < 6u; ++c) gNetIn[base + c * kMapTexels + t] = gOneShot[base + c * kMapTexels + t];
    gNetIn[base + 6u * kMapTexels + t] = normalizeDistance(gOneShot[base + 6u * kMapTexels + t], meanDistance);
  }
}
