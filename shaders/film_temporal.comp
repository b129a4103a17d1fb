#version 460
// film_temporal: a shot's frame blended with the frames before it where they saw the same
// surface (src/render/temporal_reuse.h; SVGF's temporal accumulation, Schied et al. 2017,
// section 4.1, with a statistical test in place of its fixed blend). Each pixel's first-hit
// point (its depth through the pixel's centre) is projected into the previous frame; of the
// four history pixels around it, those that saw the same surface (a normal within 25 degrees,
// the point within 1 % of its depth of their plane, no light seen directly) are averaged
// bilinearly. Colour is blended demodulated by the albedo (texture is not history), with the
// sample counts as weights, the history's capped at maxHistory times the frame's own so that
// old light fades. History whose luminance is more than rejectSigma standard errors from the
// frame's is dropped: moved shadows, view-dependent reflections, what the geometry tests miss.
#extension GL_GOOGLE_include_directive : require
#include "shared/temporal.h"
#include "lib/camera.glsl"
#include "lib/sampling.glsl"  // luminance

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
layout(push_constant) uniform PushBlock { TemporalPush gPush; };

// What colour is divided by (as the a-trous filter's): the albedo, or 1 where the first hit
// has (almost) none, whose light is blended as it is.
vec3 demodulator(vec3 albedo) {
  return luminance(albedo) < 1e-3 ? vec3(1.0) : max(albedo, vec3(1e-3));
}

vec3 unitNormal(vec3 n) {
  const float len2 = dot(n, n);
  return len2 > 1e-12 ? n * inversesqrt(len2) : vec3(0.0);
}

// The point at view-axis depth z through the centre of film pixel (x, y) of frame f.
vec3 surfacePoint(CameraFrame f, vec2 pixel, float z) {
  const vec2 ndc = vec2((pixel.x + float(f.originX)) / float(f.imageWidth) * 2.0 - 1.0,
                        1.0 - (pixel.y + float(f.originY)) / float(f.imageHeight) * 2.0);
  const vec3 local = vec3(ndc.x * f.tanHalfFovY * f.aspect, ndc.y * f.tanHalfFovY, -1.0);
  return f.cameraOrigin.xyz + z * (local.x * f.cameraRight.xyz + local.y * f.cameraUp.xyz +
                                   local.z * f.cameraBack.xyz);
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= gPush.width || p.y >= gPush.height) return;
  const uint i = p.y * gPush.width + p.x;
  const float own = gPush.samples;
  const vec4 albedo = gAlbedo[i];
  const vec4 normal = gNormal[i];
  gIndirect[i].w = own;
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
    if (r.x < 0 || r.y < 0 || r.x >= int(gPush.width) || r.y >= int(gPush.height)) continue;
    const uint j = uint(r.y) * gPush.width + uint(r.x);
    const vec4 ha = gHAlbedo[j];
    const vec4 hn = gHNormal[j];
    if (ha.w <= 0.0 || hn.w > 0.0) continue;
    if (dot(unitNormal(hn.xyz), n) < 0.9) continue;
    const vec3 y = surfacePoint(gCameras.previous, vec2(r) + 0.5, ha.w);
    if (abs(dot(n, y - x)) > 0.01 * albedo.w) continue;
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
  // The frame's own variance estimate is itself noisy: a pixel whose few samples all came
  // out dark has a small one and would reject good history, leaving a dark speck. The
  // history's spread per sample, scaled to the frame's samples, stands in where it is larger.
  const float gap = luminance(hc) - luminance(cc);
  const float sigma = gPush.rejectSigma;
  const float expected = max(cVar, hVar * (hCount / wSum) / own);
  if (gap * gap > sigma * sigma * (expected + hVar) + 1e-12 * (1.0 + luminance(cc) * luminance(cc)))
    return;

  const float total = own + history;
  const float a = own / total, b = history / total;
  gCombined[i] = vec4((a * cc + b * hc) * d, (a * a * cVar + b * b * hVar) * l * l);
  gDirect[i].rgb = (a * gDirect[i].rgb / d + b * hd) * d;
  gIndirect[i] = vec4((a * gIndirect[i].rgb / d + b * hi) * d, total);
}
