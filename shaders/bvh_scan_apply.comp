#version 460
// bvh_scan_apply: last step of the exclusive scan: each segment scanned serially from its
// scanned partial sum, in place. triangleCount = element count, param = segment count.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kScanBindingData) buffer Data { uint gData[]; };
layout(std430, binding = kScanBindingPartials) readonly buffer Partials { uint gPartials[]; };
layout(push_constant) uniform PushBlock { BuildPush gPush; };

void main() {
  uint s = gl_GlobalInvocationID.x;
  if (s >= gPush.param) return;
  uint begin = s * kScanSegment;
  uint end = min(begin + kScanSegment, gPush.triangleCount);
  uint running = gPartials[s];
  for (uint i = begin; i < end; ++i) {
    uint v = gData[i];
    gData[i] = running;
    running += v;
  }
}
