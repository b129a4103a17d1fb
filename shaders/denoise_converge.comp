#version 460
// denoise_converge: the denoised colour moved back towards the film's own colour where the two
// differ by more than the film's noise explains (shared/denoise.h, "Convergence"). A denoiser's
// bias (texture and shading detail averaged away) stays however many samples the film has, so
// without this step a denoised image stops converging; with it, the image returns to the film
// as the film's noise falls.
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
  const vec3 normal = gNormal[ip].xyz;
  float gap = 0.0, noise = 0.0, level = 0.0, count = 0.0;
  for (int dy = -kConvergeRadius; dy <= kConvergeRadius; ++dy)
    for (int dx = -kConvergeRadius; dx <= kConvergeRadius; ++dx) {
      const ivec2 q = p + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      const uint iq = uint(q.y) * gPush.width + uint(q.x);
      const vec4 guide = gNormal[iq];
      if (guide.w > 0.0) continue;  // a lamp's variance or gap is not this surface's
      const float w = convergeWeight(normal, guide.xyz);
      const vec4 film = gColour[iq];
      const float denoised = max(luminance(gDenoised[iq].rgb), 0.0);
      const float g = luminance(film.rgb) - denoised;
      gap += w * g * g;
      noise += w * (film.w > 0.0 ? film.w : denoised * denoised / float(max(gPush.samples, 1u)));
      level += w * denoised;
      count += w;
    }
  const float weights = max(count, 1e-6);
  const float k = convergeNoiseFactor(kConvergeNoiseScale, noise, level, weights);
  const float ratio = k * noise / gap;  // NaN where both are infinite: then d is kept
  const float lambda = gap > 0.0 && !isnan(ratio) ? clamp(1.0 - ratio, 0.0, 1.0) : 0.0;
  gOut[ip] = vec4(mix(gDenoised[ip].rgb, gColour[ip].rgb, lambda), 0.0);
}
