#version 460
// denoise_converge: the denoised colour moved back towards the film's own colour where the two
// differ by more than the film's noise explains (shared/denoise.h, "Convergence"). A denoiser's
// bias (texture and shading detail averaged away) stays however many samples the film has, so
// without this step a denoised image stops converging; with it, the image returns to the film
// as the film's noise falls.
// In: colour (the film's: rgb, w its luminance variance), denoised (rgb). Out: rgb, w 0.
#extension GL_GOOGLE_include_directive : require
#include "shared/denoise.h"
#include "lib/sampling.glsl"  // luminance

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(std430, binding = kBindingColour) readonly buffer Colour { vec4 gColour[]; };
layout(std430, binding = kBindingDenoised) readonly buffer Denoised { vec4 gDenoised[]; };
layout(std430, binding = kBindingOut) writeonly buffer Out { vec4 gOut[]; };
layout(push_constant) uniform PushBlock { DenoisePush gPush; };

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  const ivec2 size = ivec2(gPush.width, gPush.height);
  if (any(greaterThanEqual(p, size))) return;
  float gap = 0.0, noise = 0.0, level = 0.0, count = 0.0;
  for (int dy = -kConvergeRadius; dy <= kConvergeRadius; ++dy)
    for (int dx = -kConvergeRadius; dx <= kConvergeRadius; ++dx) {
      const ivec2 q = p + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      const uint iq = uint(q.y) * gPush.width + uint(q.x);
      const vec4 film = gColour[iq];
      const float denoised = luminance(gDenoised[iq].rgb);
      const float g = luminance(film.rgb) - denoised;
      gap += g * g;
      noise += max(film.w, 0.0);
      level += max(denoised, 0.0);
      count += 1.0;
    }
  // The window's relative standard error: its mean variance's root over its mean level.
  const float k = 1.0 + kConvergeNoiseScale * sqrt(noise / count) / max(level / count, 1e-4);
  const float lambda = gap > 0.0 ? clamp(1.0 - k * noise / gap, 0.0, 1.0) : 0.0;
  const uint ip = uint(p.y) * gPush.width + uint(p.x);
  gOut[ip] = vec4(mix(gDenoised[ip].rgb, gColour[ip].rgb, lambda), 0.0);
}
