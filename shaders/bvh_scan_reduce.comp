#version 460
// bvh_scan_reduce: first step of an exclusive scan: partials[s] = sum of segment s
// (kScanSegment elements). triangleCount = element count, param = segment count.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kScanBindingData) readonly buffer Data { uint gData[]; };
layout(std430, binding = kScanBindingPartials) writeonly buffer Partials { uint gPartials[]; };
layout(push_constant) uniform PushBlock { BuildPush gPush; };

void main() {
  uint s = gl_GlobalInvocationID.x;
  if (s >= gPush.param) return;
  uint begin = s * kScanSegment;
  uint end = min(begin + kScanSegment, gPush.triangleCount);
  uint sum = 0u;
  for (uint i = begin; i < end; ++i) sum += gData[i];
  gPartials[s] = sum;
}
