#version 460
// denoise_kernel_apply: one level of the kernel-predicting denoiser (tools/image_unet.py
// apply_kernels) on one tile. Each pixel's 25 logits of this level (channels level x 25 on, of
// the network's output tensor) are a softmax over the taps inside the tile, `step` pixels
// apart, that average the previous level's colour. The first level (kFirst) reads the image
// colour demodulated by the albedo (image_unet.demodulator), exposed by e and compressed to
// t = x / (1 + lum(x)), repeating the last row and column as the network's input does; the
// last (kLast) inverts that, re-modulates and writes the tile's core pixels into the image.
// Between levels the colour lives in tile-sized vec4 buffers. A pixel that saw light directly
// (normal.w > 0, shared/denoise.h) keeps its own colour and is no other pixel's tap; the
// softmax runs over the taps that remain. kGuided (shared/denoise.h kKernelFactors*): with
// kKernelFactorsGeometry (osr_image_kpn_v2) each tap's logit gets the logarithm of the fixed
// normal and depth edge-stopping factors added, so the network only learns what the geometry
// cannot tell; with kKernelFactorsFilter (osr_image_kpn_v3) also those of the a-trous filter's
// B3-spline and variance-scaled luminance factors, so the kernels start as the filter; with
// kKernelFactorsStraddle (osr_image_kpn_v4) the normal factor of a pixel that straddles an
// edge compares mean normals, as the filter's does (lib/film_guides.glsl). Like the
// filter it averages linear colour (its factors keep fireflies out of their neighbours, which
// the compression does for the others) and the variance of its luminance (image colour .w, the
// film's, demodulated and exposed at the first level), passed on in the tile buffers' w.
#extension GL_GOOGLE_include_directive : require
#include "shared/denoise.h"
#include "lib/film_guides.glsl"  // normalLogFactor
#include "lib/sampling.glsl"  // luminance

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(constant_id = kSpecKernelFirst) const uint kFirst = 0;
layout(constant_id = kSpecKernelLast) const uint kLast = 0;
layout(constant_id = kSpecKernelGuided) const uint kGuided = 0;
layout(std430, binding = kBindingColour) readonly buffer Colour { vec4 gColour[]; };
layout(std430, binding = kBindingAlbedo) readonly buffer Albedo { vec4 gAlbedo[]; };
layout(std430, binding = kBindingNormal) readonly buffer Normal { vec4 gNormal[]; };
layout(std430, binding = kBindingExposure) readonly buffer Sums { ExposureSums gSums[]; };
layout(std430, binding = kBindingTensor) readonly buffer Tensor { float gTensor[]; };
layout(std430, binding = kBindingOut) writeonly buffer Out { vec4 gOut[]; };
layout(push_constant) uniform PushBlock { DenoisePush gPush; };

// The image pixel behind tile pixel t (the padding repeats the last row and column).
uint imagePixel(ivec2 t) {
  const uint x = min(gPush.tileX + uint(t.x), gPush.width - 1u);
  const uint y = min(gPush.tileY + uint(t.y), gPush.height - 1u);
  return y * gPush.width + x;
}

// image_unet.demodulator: the albedo, floored, or 1 where there is (almost) none.
vec3 modulator(uint p) {
  const vec3 a = gAlbedo[p].rgb;
  return luminance(a) < kKernelDemodulateMin ? vec3(1.0) : max(a, vec3(kKernelDemodulateMin));
}

bool seesLight(ivec2 t) { return gNormal[imagePixel(t)].w > 0.0; }

// The first hit's depth at padded-image pixel g, reads clamped into the image (the padding
// repeats the last row and column; image_unet.depth_gradient repeats the edges).
float depthAt(ivec2 g) {
  const ivec2 c = clamp(g, ivec2(0), ivec2(gPush.width, gPush.height) - 1);
  return gAlbedo[uint(c.y) * gPush.width + uint(c.x)].w;
}

// image_unet.depth_gradient along one axis: the smaller one-sided depth difference, only
// the one inside the padded image at its edge.
float depthSlope(ivec2 g, ivec2 axis) {
  const float z = depthAt(g);
  float slope = kGuideSlopeNone;
  if (all(lessThan(g + axis, ivec2(gPush.paddedWidth, gPush.paddedHeight)))) slope = abs(depthAt(g + axis) - z);
  if (all(greaterThanEqual(g - axis, ivec2(0)))) slope = min(slope, abs(z - depthAt(g - axis)));
  return slope;
}

// image_unet.guide_logits: log of tap q's fixed factor for tile pixel t, whose film normal
// (the mean over its samples), depth and depth gradient are np, zp, gradZ.
float guideLogit(ivec2 t, ivec2 q, vec3 np, float zp, float gradZ) {
  if (q == t) return 0.0;
  const float zq = gAlbedo[imagePixel(q)].w;
  const float none = kGuideSigmaNormal * log(kGuideCosMin);
  if (zp <= 0.0 || zq <= 0.0) return (zp > 0.0) == (zq > 0.0) ? 0.0 : none;
  const float straddle = kGuided == kKernelFactorsStraddle ? kGuideStraddleLength : 0.0;
  const float normal = normalLogFactor(np, gNormal[imagePixel(q)].xyz, kGuideSigmaNormal, kGuideCosMin, straddle,
                                       kGuideStraddleSigma);
  const float scale = kGuideSigmaDepth * gradZ * length(vec2(q - t)) + kGuideDepthFloor * zp;
  return normal - abs(zp - zq) / max(scale, 1e-30);
}

// The level's input at tile pixel t: the colour (compressed, or linear with the filter's
// factors) and with them the variance of its luminance: the film's, demodulated and exposed.
vec4 levelInput(ivec2 t) {
  if (kFirst != 0u) {
    const uint p = imagePixel(t);
    const vec3 m = modulator(p);
    const float e = gSums[kExposurePartials].exposure;
    const vec4 c = gColour[p];
    const vec3 x = max(c.rgb, vec3(0.0)) / m * e;
    if (kGuided >= kKernelFactorsFilter) {
      const float lm = luminance(m);
      return vec4(x, max(c.w, 0.0) * e * e / (lm * lm));
    }
    return vec4(x / (1.0 + luminance(x)), 0.0);
  }
  return gColour[uint(t.y) * gPush.tileWidth + uint(t.x)];
}

// image_unet.filter_logits: the luminance factor's scale at tile pixel t, from the level's
// variance blurred 3 x 3 (weights 1 2 1 per axis, over the pixels inside the tile).
float filterSigma(ivec2 t) {
  const float g[2] = float[2](0.5, 0.25);
  float sum = 0.0, weight = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const ivec2 q = t + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || q.x >= int(gPush.tileWidth) || q.y >= int(gPush.tileHeight)) continue;
      const float k = g[abs(dx)] * g[abs(dy)];
      sum += k * levelInput(q).w;
      weight += k;
    }
  return kFilterSigmaLuminance * sqrt(max(sum / weight, 0.0)) + kFilterVarianceFloor;
}

// The logarithm of the a-trous filter's factors on tap i whose luminance is lq, for a pixel of
// luminance lp and scale sigma.
float filterLogit(uint i, float lp, float lq, float sigma) {
  const float h[3] = float[3](0.375, 0.25, 0.0625);
  const ivec2 offset = abs(ivec2(i % kKernelSize, i / kKernelSize) - int(kKernelSize / 2u));
  return log(h[offset.x] * h[offset.y]) - abs(lp - lq) / sigma;
}

// Tap i of pixel t's kernel at this level's step, or (-1, -1) when it is outside the tile or
// does not count: a light's pixel, or any but the centre when t itself sees light.
ivec2 tapAt(ivec2 t, uint i, bool lit) {
  const ivec2 offset = ivec2(i % kKernelSize, i / kKernelSize) - int(kKernelSize / 2u);
  const ivec2 q = t + offset * int(gPush.step);
  const ivec2 size = ivec2(gPush.tileWidth, gPush.tileHeight);
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) return ivec2(-1);
  if (offset != ivec2(0) && (lit || seesLight(q))) return ivec2(-1);
  return q;
}

void main() {
  const ivec2 size = ivec2(gPush.tileWidth, gPush.tileHeight);
  // The last level runs over the core only; the others over the whole tile.
  const ivec2 origin = kLast != 0u ? ivec2(gPush.coreX0 - gPush.tileX, gPush.coreY0 - gPush.tileY) : ivec2(0);
  const ivec2 end = kLast != 0u ? ivec2(gPush.coreX1 - gPush.tileX, gPush.coreY1 - gPush.tileY) : size;
  const ivec2 t = origin + ivec2(gl_GlobalInvocationID.xy);
  if (t.x >= end.x || t.y >= end.y) return;
  const uint plane = gPush.tileWidth * gPush.tileHeight;
  const uint base = uint(findLSB(gPush.step)) * kKernelTaps * plane + uint(t.y) * gPush.tileWidth + uint(t.x);
  const bool lit = seesLight(t);
  vec3 np = vec3(0.0);
  float zp = 0.0, gradZ = 0.0;
  float lp = 0.0, sigma = 1.0;
  if (kGuided >= kKernelFactorsFilter) {
    lp = luminance(levelInput(t).rgb);
    sigma = filterSigma(t);
  }
  if (kGuided != 0u) {
    const ivec2 g = ivec2(gPush.tileX, gPush.tileY) + t;
    np = gNormal[imagePixel(t)].xyz;
    zp = depthAt(g);
    gradZ = max(depthSlope(g, ivec2(1, 0)), depthSlope(g, ivec2(0, 1)));
  }
  // Each tap's input is read once: the filter's factors need its luminance before the softmax.
  float logits[kKernelTaps];
  vec4 inputs[kKernelTaps];
  float top = -3.0e38;
  for (uint i = 0u; i < kKernelTaps; ++i) {
    const ivec2 q = tapAt(t, i, lit);
    if (q.x < 0) continue;
    inputs[i] = levelInput(q);
    logits[i] = gTensor[base + i * plane] + (kGuided != 0u ? guideLogit(t, q, np, zp, gradZ) : 0.0);
    if (kGuided >= kKernelFactorsFilter) logits[i] += filterLogit(i, lp, luminance(inputs[i].rgb), sigma);
    top = max(top, logits[i]);
  }
  vec3 sum = vec3(0.0);
  float weights = 0.0, sumVariance = 0.0;
  for (uint i = 0u; i < kKernelTaps; ++i) {
    if (tapAt(t, i, lit).x < 0) continue;
    const float w = exp(logits[i] - top);
    const vec4 c = inputs[i];
    sum += w * c.rgb;
    sumVariance += w * w * c.w;
    weights += w;
  }
  const vec3 d = sum / weights;
  if (kLast != 0u) {
    const uint p = imagePixel(t);
    const vec3 x = kGuided >= kKernelFactorsFilter ? d : d / max(1.0 - luminance(d), 1e-6);
    gOut[p] = vec4(x / gSums[kExposurePartials].exposure * modulator(p), 0.0);
  } else {
    gOut[uint(t.y) * gPush.tileWidth + uint(t.x)] = vec4(d, sumVariance / (weights * weights));
  }
}
