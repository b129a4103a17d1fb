#version 460
// denoise_atrous: one iteration of the edge-aware a-trous wavelet filter of SVGF (Schied et al.
// 2017, section 4.3): a 5 x 5 B3-spline kernel with taps `step` pixels apart, each tap weighted
// by its luminance difference against sigmaLuminance x the pixel's standard deviation (the
// variance blurred 3 x 3), its depth difference against the depth gradient, and its normal's
// agreement (for a pixel that straddles an edge, with neighbours of the same mix of its faces:
// lib/film_guides.glsl normalLogFactor). The filtered variance (sum of squared weights x
// variance) feeds the next iteration. A pixel that saw light directly (normal.w > 0,
// shared/denoise.h) keeps its own colour and is no other pixel's tap. The filter runs on
// demodulated colour (colour / albedo: texture is not noise): the first iteration (kFirst)
// divides, the last (kLast) multiplies back.
// In: colour (rgb, w variance; demodulated after the first iteration), albedo (w depth),
// normal. Out: the same form; after the last iteration the filtered colour.
#extension GL_GOOGLE_include_directive : require
#include "shared/denoise.h"
#include "lib/film_guides.glsl"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(constant_id = kSpecAtrousFirst) const uint kFirst = 0;
layout(constant_id = kSpecAtrousLast) const uint kLast = 0;
layout(std430, binding = kBindingColour) readonly buffer Colour { vec4 gColour[]; };
layout(std430, binding = kBindingAlbedo) readonly buffer Albedo { vec4 gAlbedo[]; };
layout(std430, binding = kBindingNormal) readonly buffer Normal { vec4 gNormal[]; };
layout(std430, binding = kBindingOut) writeonly buffer Out { vec4 gOut[]; };
layout(push_constant) uniform PushBlock { DenoisePush gPush; };

// The iteration's input at pixel p: rgb and the variance of its luminance.
vec4 inputAt(uint p) {
  const vec4 c = gColour[p];
  if (kFirst == 0u) return c;
  const vec3 d = demodulator(gAlbedo[p].rgb);
  const float l = luminance(d);
  return vec4(c.rgb / d, max(c.w, 0.0) / (l * l));
}

bool inside(ivec2 q) { return q.x >= 0 && q.y >= 0 && q.x < int(gPush.width) && q.y < int(gPush.height); }
uint index(ivec2 q) { return uint(q.y) * gPush.width + uint(q.x); }
float depthAt(ivec2 q) { return inside(q) ? gAlbedo[index(q)].w : 0.0; }

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  const uint ip = index(p);
  const vec4 centre = inputAt(ip);
  const vec3 np = gNormal[ip].xyz;
  const float zp = gAlbedo[ip].w;
  const float lp = luminance(centre.rgb);
  const bool lit = gNormal[ip].w > 0.0;

  // The variance blurred 3 x 3 (Gaussian), as SVGF does before using it: one pixel's own
  // estimate is itself noisy.
  const float g3[2] = float[2](0.25, 0.125);
  float varBlur = 0.0, varWeight = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const ivec2 q = p + ivec2(dx, dy);
      if (!inside(q)) continue;
      const float k = g3[abs(dx)] * g3[abs(dy)] * 4.0;
      varBlur += k * inputAt(index(q)).w;
      varWeight += k;
    }
  const float sigmaL = gPush.sigmaLuminance * sqrt(max(varBlur / varWeight, 0.0)) + 1e-6;
  // Depth change per pixel (central differences; 0 beside a miss).
  const float gradZ = max(abs(depthAt(p + ivec2(1, 0)) - depthAt(p - ivec2(1, 0))),
                          abs(depthAt(p + ivec2(0, 1)) - depthAt(p - ivec2(0, 1)))) * 0.5;

  const float h[3] = float[3](0.375, 0.25, 0.0625);
  vec3 sum = vec3(0.0);
  float sumWeight = 0.0, sumVar = 0.0;
  for (int ty = -2; ty <= 2; ++ty) {
    for (int tx = -2; tx <= 2; ++tx) {
      const ivec2 q = p + ivec2(tx, ty) * int(gPush.step);
      if (!inside(q)) continue;
      const uint iq = index(q);
      if (iq != ip && (lit || gNormal[iq].w > 0.0)) continue;
      const vec4 c = inputAt(iq);
      const float zq = gAlbedo[iq].w;
      float w;
      if (zp == 0.0 || zq == 0.0) {
        w = zp == zq ? exp(-abs(lp - luminance(c.rgb)) / sigmaL) : 0.0;  // miss to miss only
      } else {
        const float dz = abs(zp - zq) / (gPush.sigmaDepth * gradZ * length(vec2(q - p)) + 1e-3 * zp);
        // The film's normal is the mean over the pixel's samples, shorter than 1 where it
        // straddles an edge. Compared by their dot product, such a pixel agreed less with
        // itself than with the face covering most of it (|n|^2 < n.m) and was replaced by it.
        const float ln = iq == ip ? 0.0
                                  : normalLogFactor(np, gNormal[iq].xyz, gPush.sigmaNormal, kGuideCosMin,
                                                    kGuideStraddleLength, kGuideStraddleSigma);
        w = exp(ln - abs(lp - luminance(c.rgb)) / sigmaL - dz);
      }
      const float k = h[abs(tx)] * h[abs(ty)] * w;
      sum += k * c.rgb;
      sumWeight += k;
      sumVar += k * k * c.w;
    }
  }
  // The centre tap always has weight h0^2 > 0: its own differences are 0 and its normal
  // factor 1.
  vec4 result = sumWeight > 0.0 ? vec4(sum / sumWeight, sumVar / (sumWeight * sumWeight)) : centre;
  if (kLast != 0u) result.rgb *= demodulator(gAlbedo[ip].rgb);
  gOut[ip] = result;
}
