#version 460
// osr_map_project: each clean map's mean radiance (pi x mean is its exact irradiance at the
// map's normal) and its irradiance as 9 SH coefficients (Ramamoorthi & Hanrahan 2001), in the
// map's frame, for the composite's Lambertian closed form at other normals. Texel solid angle:
// every texel covers pi / 1024 of projected solid angle, so d(omega) = pi / (1024 cos theta).
// Also the luminance of each texel row and of the whole map, by which osr_residual draws
// directions from the maps (lib/osr_maps.glsl sampleGatheredMaps).
// An invocation or a workgroup per map of the chunk (lib/osr_map_group.glsl). In: clean maps.
// Out: MapProjection.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/osr_maps.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
#include "lib/osr_map_group.glsl"
layout(push_constant) uniform OsrPushBlock { MapProjectPush gPush; };

void main() {
  uint local = mapOfInvocation();
  if (local >= gPush.mapCount) return;
  uint map = gPush.mapOffset + local;
  vec3 sh[9];
  for (int i = 0; i < 9; ++i) sh[i] = vec3(0.0);
  vec3 sum = vec3(0.0);
  vec4 rows[8];
  for (int i = 0; i < 8; ++i) rows[i] = vec4(0.0);
  uint base = local * 3u * kMapTexels;  // gMapClean's window starts at map mapOffset
  for (uint t = firstMapTexel(); t < kMapTexels; t += mapTexelStep()) {
    vec3 l = vec3(gMapClean[base + t], gMapClean[base + kMapTexels + t],
                  gMapClean[base + 2u * kMapTexels + t]);
    sum += l;
    uint row = t / kMapSize;
    rows[row / 4u][row % 4u] += luminance(l);
    vec2 u = (vec2(t % kMapSize, t / kMapSize) + 0.5) / float(kMapSize);
    vec3 w = hemiSquareToDirection(u);
    float dOmega = kPi / (float(kMapTexels) * max(w.z, 1e-3));
    float y[9];
    shBasis(w, y);
    for (int i = 0; i < 9; ++i) sh[i] += l * (y[i] * dOmega);
  }
  sum = mapSum(vec4(sum, 0.0)).rgb;
  for (int i = 0; i < 9; ++i) sh[i] = mapSum(vec4(sh[i], 0.0)).rgb;
  float total = 0.0;
  for (int i = 0; i < 8; ++i) {
    rows[i] = mapSum(rows[i]);
    total += rows[i].x + rows[i].y + rows[i].z + rows[i].w;
  }
  if (firstMapTexel() != 0u) return;
  // Convolution with the clamped cosine (kShCosine: A0 = pi, A1 = 2 pi / 3, A2 = pi / 4).
  gMapProjections[map].mean = vec4(sum / float(kMapTexels), total);
  for (int i = 0; i < 8; ++i) gMapProjections[map].rowLuminance[i] = rows[i];
  for (int i = 0; i < 9; ++i) gMapProjections[map].sh[i] = vec4(sh[i] * kShCosine[i], 0.0);
}
