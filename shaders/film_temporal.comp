#version 460
// film_temporal: a shot's frame blended with the frames before it where they saw the same
// surface (src/render/temporal_reuse.h; SVGF's temporal accumulation, Schied et al. 2017,
// section 4.1, with a statistical test in place of its fixed blend). Each pixel's first-hit
// point (its depth through the pixel's centre) is projected into the previous frame; of the
// four history pixels around it, those that saw the same surface (a normal within 25 degrees,
// their point within 1 % of the depth of the pixel's plane, or astride the same edge; no light
// seen directly) are averaged bilinearly. Colour is blended demodulated by the albedo (texture is not history), with the
// sample counts as weights, the history's capped at maxHistory times the frame's own so that
// old light fades. History whose luminance is further than rejectSigma spreads from the mean
// of the frame's 3 x 3 neighbourhood on the same surface is dropped: moved shadows,
// view-dependent reflections, what the geometry tests miss.
#extension GL_GOOGLE_include_directive : require
#include "shared/temporal.h"
#include "lib/camera.glsl"
#include "lib/film_guides.glsl"

layout(local_size_x = kTemporalTile, local_size_y = kTemporalTile) in;
layout(std430, binding = kBindingCombined) buffer Combined { vec4 gCombined[]; };
layout(std430, binding = kBindingDirect) buffer Direct { vec4 gDirect[]; };
layout(std430, binding = kBindingIndirect) buffer Indirect { vec4 gIndirect[]; };
layout(std430, binding = kBindingAlbedo) readonly buffer Albedo { vec4 gAlbedo[]; };
layout(std430, binding = kBindingNormal) readonly buffer Normal { vec4 gNormal[]; };
layout(std430, binding = kBindingHistoryCombined) readonly buffer HCombined { vec4 gHCombined[]; };
layout(std430, binding = kBindingHistoryDirect) readonly buffer HDirect { vec4 gHDirect[]; };
layout(std430, binding = kBindingHistoryIndirect) readonly buffer HIndirect { vec4 gHIndirect[]; };
layout(std430, binding = kBindingHistoryAlbedo) readonly buffer HAlbedo { vec4 gHAlbedo[]; };
layout(std430, binding = kBindingHistoryNormal) readonly buffer HNormal { vec4 gHNormal[]; };
layout(std430, binding = kBindingCameras) readonly buffer Cameras { TemporalCameras gCameras; };
layout(std430, binding = kBindingFrameColour) readonly buffer FrameColour { vec4 gFrameColour[]; };
layout(push_constant) uniform PushBlock { TemporalPush gPush; };

bool inside(ivec2 q) { return q.x >= 0 && q.y >= 0 && q.x < int(gPush.width) && q.y < int(gPush.height); }
uint index(ivec2 q) { return uint(q.y) * gPush.width + uint(q.x); }

// The point at view-axis depth z through the centre of film pixel (x, y) of frame f.
vec3 surfacePoint(CameraFrame f, vec2 pixel, float z) {
  const vec2 ndc = vec2((pixel.x + float(f.originX)) / float(f.imageWidth) * 2.0 - 1.0,
                        1.0 - (pixel.y + float(f.originY)) / float(f.imageHeight) * 2.0);
  const vec3 local = vec3(ndc.x * f.tanHalfFovY * f.aspect, ndc.y * f.tanHalfFovY, -1.0);
  return f.cameraOrigin.xyz + z * (local.x * f.cameraRight.xyz + local.y * f.cameraUp.xyz +
                                   local.z * f.cameraBack.xyz);
}

// Mean and spread (variance over pixels) of the frame's demodulated luminance over the 3 x 3
// pixels around p that see the surface p sees (a normal within 25 degrees, no light seen).
vec2 neighbourhood(ivec2 p, vec3 n) {
  float sum = 0.0, sumSq = 0.0, count = 0.0;
  for (int k = 0; k < 9; ++k) {
    const ivec2 q = p + ivec2(k % 3 - 1, k / 3 - 1);
    if (!inside(q)) continue;
    const uint j = index(q);
    const vec4 a = gAlbedo[j];
    const vec4 m = gNormal[j];
    if (a.w <= 0.0 || m.w > 0.0 || dot(unitNormal(m.xyz), n) < 0.9) continue;
    const float l = luminance(gFrameColour[j].rgb / demodulator(a.rgb));
    sum += l, sumSq += l * l, count += 1.0;
  }
  const float mean = sum / max(count, 1.0);
  return vec2(mean, max(sumSq / max(count, 1.0) - mean * mean, 0.0));
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= gPush.width || p.y >= gPush.height) return;
  const uint i = p.y * gPush.width + p.x;
  const float own = gPush.samples;
  const vec4 albedo = gAlbedo[i];
  const vec4 normal = gNormal[i];
  gIndirect[i].w = own;
  // Without history (the first frame, or one after the scene changed) the history layers hold
  // whatever they held, maybe never written: nothing of them is read.
  if (gPush.maxHistory <= 0.0) return;
  if (albedo.w <= 0.0 || normal.w > 0.0) return;  // a miss, or a light seen directly

  const vec3 n = unitNormal(normal.xyz);
  const vec3 x = surfacePoint(gCameras.current, vec2(p) + 0.5, albedo.w);
  vec2 q;
  if (!cameraProject(gCameras.previous, x, q)) return;
  const vec2 f = q - 0.5;
  const ivec2 q0 = ivec2(floor(f));
  const vec2 t = f - vec2(q0);
  vec3 hc = vec3(0.0), hd = vec3(0.0), hi = vec3(0.0);
  float hVar = 0.0, hCount = 0.0, wSum = 0.0;
  for (int k = 0; k < 4; ++k) {
    const ivec2 o = ivec2(k & 1, k >> 1);
    const ivec2 r = q0 + o;
    if (!inside(r)) continue;
    const uint j = index(r);
    const vec4 ha = gHAlbedo[j];
    const vec4 hn = gHNormal[j];
    if (ha.w <= 0.0 || hn.w > 0.0) continue;
    const float agree = dot(unitNormal(hn.xyz), n);
    const vec3 y = surfacePoint(gCameras.previous, vec2(r) + 0.5, ha.w);
    // A pixel astride an edge has the mean depth and normal of two faces (its normal shorter
    // than 1): its point is off both, so no plane holds it, and the mixture changes as the
    // edge moves under the pixel. A history pixel astride the same edge is taken where it is
    // at the depth the point projects to, with a normal within 45 degrees.
    const bool astride = dot(normal.xyz, normal.xyz) < 0.95 && dot(hn.xyz, hn.xyz) < 0.95;
    const bool samePlane = agree >= 0.9 && abs(dot(n, y - x)) <= 0.01 * albedo.w;
    const bool sameEdge =
        astride && agree >= 0.7 && abs(cameraDepth(gCameras.previous, x) - ha.w) <= 0.01 * ha.w;
    if (!samePlane && !sameEdge) continue;
    const float w = (o.x == 1 ? t.x : 1.0 - t.x) * (o.y == 1 ? t.y : 1.0 - t.y);
    const vec3 d = demodulator(ha.rgb);
    const float l = luminance(d);
    const vec4 c = gHCombined[j];
    hc += w * c.rgb / d;
    hd += w * gHDirect[j].rgb / d;
    hi += w * gHIndirect[j].rgb / d;
    hVar += w * max(c.w, 0.0) / (l * l);
    hCount += w * gHIndirect[j].w;
    wSum += w;
  }
  // A sliver of a matching pixel is not enough to stand for one.
  if (wSum < 0.25) return;
  hc /= wSum, hd /= wSum, hi /= wSum, hVar /= wSum;
  const float history = min(hCount / wSum, gPush.maxHistory * own);

  const vec4 c = gCombined[i];
  const vec3 d = demodulator(albedo.rgb);
  const float l = luminance(d);
  const vec3 cc = c.rgb / d;
  const float cVar = max(c.w, 0.0) / (l * l);
  // History that the frame's neighbourhood does not bear out is dropped: its mean and spread
  // over the 3 x 3 pixels of the same surface (or the pixel's own variance, if larger), not
  // the pixel alone. A firefly among the frame's own samples would otherwise make the history
  // look wrong and keep its full strength, where blending dilutes it; and at a few samples a
  // pixel's own variance estimate is itself noisy (one whose samples all came out dark has
  // almost none).
  const vec2 around = neighbourhood(ivec2(p), n);
  const float gap = luminance(hc) - around.x;
  const float sigma = gPush.rejectSigma;
  const float spread = max(around.y, cVar) + hVar;
  if (gap * gap > sigma * sigma * spread + 1e-12 * (1.0 + around.x * around.x)) return;

  const float total = own + history;
  const float a = own / total, b = history / total;
  gCombined[i] = vec4((a * cc + b * hc) * d, (a * a * cVar + b * b * hVar) * l * l);
  gDirect[i].rgb = (a * gDirect[i].rgb / d + b * hd) * d;
  gIndirect[i] = vec4((a * gIndirect[i].rgb / d + b * hi) * d, total);
}
