#version 460
// pt_bsdf_probe: test pass for shaders/lib/bsdf.glsl. Inputs: ProbeCase[] (material + wo).
// Eval mode: out[case * thetaCount * phiCount + cell] = f*|cos| and pdf at the cell centre of
// a (theta, phi) grid over the sphere, for quadrature on the CPU. Sample mode:
// out[case * samplesPerCase + i] = one bsdfSample plus bsdfEval at its direction. Guide mode:
// out[case].value = the denoisers' albedo guide (denoiseAlbedo) at wo.
#extension GL_GOOGLE_include_directive : require
#include "shared/bsdf.h"
#include "lib/rng.glsl"
#include "lib/bsdf.glsl"

layout(local_size_x = kProbeWorkgroupSize) in;
layout(std430, binding = kProbeBindingCases) readonly buffer Cases { ProbeCase gCases[]; };
layout(std430, binding = kProbeBindingOut) writeonly buffer Outs { ProbeOut gOut[]; };
layout(push_constant) uniform PushBlock { ProbePush gPush; };

void main() {
  uint perCase = gPush.mode == kProbeEval    ? gPush.thetaCount * gPush.phiCount
                 : gPush.mode == kProbeGuide ? 1u
                                             : gPush.samplesPerCase;
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * kProbeWorkgroupSize;
  if (i >= perCase * gPush.caseCount) return;
  uint c = i / perCase;
  uint k = i % perCase;
  BsdfParams p = gCases[c].params;
  vec3 wo = gCases[c].wo.xyz;
  ProbeOut o;
  o.evalValue = vec3(0.0);
  o.evalPdf = 0.0;
  o.flags = 0u;
  if (gPush.mode == kProbeEval) {
    uint it = k / gPush.phiCount;
    uint ip = k % gPush.phiCount;
    float theta = (float(it) + 0.5) * kPi / float(gPush.thetaCount);
    float phi = (float(ip) + 0.5) * 2.0 * kPi / float(gPush.phiCount);
    o.wi = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
    o.value = bsdfEval(p, wo, o.wi, o.pdf);
    o.flags = 2u;
  } else if (gPush.mode == kProbeGuide) {
    o.wi = wo;
    o.value = denoiseAlbedo(p, wo);
    o.pdf = 0.0;
  } else {
    Rng rng = rngInit(k, c, gPush.seed);
    BsdfSample s;
    bool ok = bsdfSample(p, wo, rngNext3(rng), s);
    o.wi = s.wi;
    o.value = ok ? s.weight : vec3(0.0);
    o.pdf = s.pdf;
    o.flags = (s.delta ? 1u : 0u) | (ok ? 2u : 0u);
    if (ok && !s.delta) o.evalValue = bsdfEval(p, wo, s.wi, o.evalPdf);
  }
  gOut[i] = o;
}
