#version 460
// osr_hemisphere_probe: evaluates shared/hemisphere.h on the device for a list of cases, so
// tests/osr/test_hemisphere.cpp can hold the GLSL mapping to its C++ twin.
// In/out: HemiProbeCase[count] (count = the push constant).
#extension GL_GOOGLE_include_directive : require
#include "shared/hemisphere.h"

layout(local_size_x = kHemiProbeWorkgroupSize) in;
layout(std430, binding = kHemiProbeBindingCases) buffer Cases { HemiProbeCase gCases[]; };
layout(push_constant) uniform PushBlock { uint gCount; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= gCount) return;
  HemiProbeCase c = gCases[i];
  vec3 d = hemiSquareToDirection(c.square.xy);
  c.toDirection = vec4(d, 0.0);
  c.square.zw = hemiDirectionToSquare(d);
  c.toSquare = vec4(hemiDirectionToSquare(c.direction.xyz), 0.0, 0.0);
  mat3 f = hemiFrame(c.normal.xyz);
  c.frameT = vec4(f[0], 0.0);
  c.frameB = vec4(f[1], 0.0);
  gCases[i] = c;
}
