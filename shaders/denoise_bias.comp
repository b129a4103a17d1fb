#version 460
// denoise_bias: the denoised colour plus the film's mean gap from it over the pixel's 5 x 5
// neighbours of the same geometry, shrunk where that mean is what the film's noise explains
// (shared/denoise.h, "Convergence"). A denoiser's bias is smooth along a face (light spread
// from the next face into a band beside their edge), so the window's mean gap measures it with
// a fraction of one pixel's noise, where denoise_converge.comp, which runs next, can only
// return a pixel to its own film colour, noise and all.
// In: colour (the film's: rgb, w its luminance variance), normal (the film's mean normal; w: the
// share of light seen directly), denoised (rgb). Out: rgb, w 0.
#extension GL_GOOGLE_include_directive : require
#include "shared/denoise.h"
#include "lib/converge_window.glsl"
#include "lib/sampling.glsl"  // luminance

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(std430, binding = kBindingColour) readonly buffer Colour { vec4 gColour[]; };
layout(std430, binding = kBindingNormal) readonly buffer Normal { vec4 gNormal[]; };
layout(std430, binding = kBindingDenoised) readonly buffer Denoised { vec4 gDenoised[]; };
layout(std430, binding = kBindingOut) writeonly buffer Out { vec4 gOut[]; };
layout(push_constant) uniform PushBlock { DenoisePush gPush; };

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  const ivec2 size = ivec2(gPush.width, gPush.height);
  if (any(greaterThanEqual(p, size))) return;
  const uint ip = uint(p.y) * gPush.width + uint(p.x);
  const vec4 centre = gNormal[ip];
  const vec3 denoisedHere = gDenoised[ip].rgb;
  if (centre.w > 0.0) {  // a light seen directly is kept as the denoiser kept it
    gOut[ip] = vec4(denoisedHere, 0.0);
    return;
  }
  vec3 gap = vec3(0.0);
  float sumVariance = 0.0, noise = 0.0, level = 0.0, count = 0.0;  // sumVariance: of sum(w x)
  for (int dy = -kBiasRadius; dy <= kBiasRadius; ++dy)
    for (int dx = -kBiasRadius; dx <= kBiasRadius; ++dx) {
      const ivec2 q = p + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      const uint iq = uint(q.y) * gPush.width + uint(q.x);
      const vec4 guide = gNormal[iq];
      if (guide.w > 0.0) continue;  // a lamp's variance or gap is not this surface's
      const float w = convergeWeight(centre.xyz, guide.xyz);
      const vec4 film = gColour[iq];
      const vec3 denoised = gDenoised[iq].rgb;
      const float l = max(luminance(denoised), 0.0);
      const float v = film.w > 0.0 ? film.w : l * l / float(max(gPush.samples, 1u));
      gap += w * (film.rgb - denoised);
      sumVariance += w * w * v;
      noise += w * v;
      level += w * l;
      count += w;
    }
  const float weights = max(count, 1e-6);
  const vec3 meanGap = gap / weights;
  const float g = luminance(meanGap);
  const float k = convergeNoiseFactor(kBiasNoiseScale, noise, level, weights);
  const float ratio = k * sumVariance / (weights * weights * g * g);
  const float lambda = clamp(1.0 - ratio, 0.0, 1.0);
  // A non-finite value in the window (a NaN or Inf that reached the film) stays out of the
  // pixel: it is kept as denoised, where the per-pixel pass after this confines such a value
  // to its own pixel.
  const bool finite = !any(isnan(meanGap)) && !any(isinf(meanGap)) && !isnan(ratio);
  gOut[ip] = vec4(finite && g * g > 0.0 ? denoisedHere + lambda * meanGap : denoisedHere, 0.0);
}
