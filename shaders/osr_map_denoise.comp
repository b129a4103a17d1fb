#version 460
// osr_map_denoise: the clean radiance map of each map of the chunk, by the denoiser chosen
// with specialization constant kOsrSpecDenoiser:
//  - kDenoiserUnet: the U-Net's output y back to radiance, exp(y) - 1, then each channel
//    scaled so its mean equals the one-shot map's (DESIGN.md "Normalization"): the network
//    redistributes light over the hemisphere, the irradiance stays the traced one;
//  - kDenoiserBlur: a fixed Gaussian (sigma 1 texel, 5 x 5, clamped at the square's edges)
//    of the one-shot radiance, renormalized to keep each channel's mean;
//  - kDenoiserNone: the one-shot radiance as traced.
// An invocation or a workgroup per map (lib/osr_map_group.glsl); nothing for the maps the cache
// gave (MapCacheRef kMapCacheReuse).
// In: one-shot maps, MapStats, U-Net output, MapCacheRef. Out: clean maps.
#extension GL_GOOGLE_include_directive : require
#include "shared/osr.h"

layout(constant_id = kOsrSpecDenoiser) const uint kDenoiser = kDenoiserUnet;
layout(constant_id = kOsrSpecNetOutput) const uint kNetOutput = kNetOutputRescaled;
layout(local_size_x = kOsrWorkgroupSize) in;
#include "lib/osr_map_group.glsl"
layout(std430, binding = kOsrBindingMapClean) buffer OsrMapClean { float gMapClean[]; };
layout(std430, binding = kOsrBindingMapOneShot) readonly buffer OsrOneShot { float gOneShot[]; };
layout(std430, binding = kOsrBindingMapStats) readonly buffer OsrStats { MapStats gStats[]; };
layout(std430, binding = kOsrBindingNetOut) readonly buffer OsrNetOut { float gNetOut[]; };
layout(std430, binding = kOsrBindingCacheRefs) readonly buffer OsrCacheRefs { MapCacheRef gCacheRefs[]; };
layout(push_constant) uniform OsrPushBlock { MapDenoisePush gPush; };

float sourceValue(uint local, uint c, uint t) {
  if (kDenoiser == kDenoiserUnet)
    return exp(min(gNetOut[(local * 3u + c) * kMapTexels + t], 80.0)) - 1.0;
  return gOneShot[(local * kMapChannels + c) * kMapTexels + t];
}

float blurred(uint local, uint c, uint t) {
  const float kGauss[3] = float[3](0.40262, 0.24420, 0.05448);  // sigma 1, taps 0, 1, 2
  int x = int(t % kMapSize), y = int(t / kMapSize);
  float sum = 0.0, wsum = 0.0;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      int sx = x + dx, sy = y + dy;
      if (sx < 0 || sy < 0 || sx >= int(kMapSize) || sy >= int(kMapSize)) continue;
      float w = kGauss[abs(dx)] * kGauss[abs(dy)];
      sum += w * gOneShot[(local * kMapChannels + c) * kMapTexels + uint(sy) * kMapSize + uint(sx)];
      wsum += w;
    }
  }
  return sum / wsum;
}

void main() {
  uint local = mapOfInvocation();
  if (local >= gPush.mapCount) return;
  // A map the cache gave was not traced: osr_cache_lookup wrote its clean map.
  if (gCacheRefs[gPush.mapOffset + local].action == kMapCacheReuse) return;
  uint out0 = local * 3u * kMapTexels;  // gMapClean's window starts at map mapOffset
  vec3 target = gStats[local].meanRadiance.rgb;
  uint t0 = firstMapTexel(), dt = mapTexelStep();
  for (uint c = 0u; c < 3u; ++c) {
    uint base = out0 + c * kMapTexels;
    if (kDenoiser == kDenoiserUnet && kNetOutput == kNetOutputAbsolute) {
      // The network predicts the level too (a 1-path map's mean is its noisiest statistic).
      float unit = 10.0 * gStats[local].meanRadiance.w;
      for (uint t = t0; t < kMapTexels; t += dt)
        gMapClean[base + t] = unit * max(sourceValue(local, c, t), 0.0);
      continue;
    }
    if (kDenoiser == kDenoiserNone) {
      for (uint t = t0; t < kMapTexels; t += dt)
        gMapClean[base + t] = gOneShot[(local * kMapChannels + c) * kMapTexels + t];
      continue;
    }
    // Each texel's value is computed once, stored, and rescaled in place once the mean is
    // known (computing it again for the rescale doubled the blur's 25 taps). Each invocation
    // rescales only the texels it wrote.
    float sum = 0.0;
    for (uint t = t0; t < kMapTexels; t += dt) {
      float v = max(kDenoiser == kDenoiserBlur ? blurred(local, c, t) : sourceValue(local, c, t), 0.0);
      gMapClean[base + t] = v;
      sum += v;
    }
    sum = mapSum(vec4(sum)).x;
    float mean = sum / float(kMapTexels);
    // A map the network made black while the traced one is not: fall back to a flat map.
    float scale = mean > 0.0 ? target[c] / mean : 0.0;
    for (uint t = t0; t < kMapTexels; t += dt)
      gMapClean[base + t] = mean > 0.0 ? gMapClean[base + t] * scale : target[c];
  }
}
