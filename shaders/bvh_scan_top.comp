#version 460
// bvh_scan_top: exclusive scan of the segment sums by a single invocation (a few thousand
// sums at most: see kScanSegment), so no cross-workgroup coordination is needed.
// param = segment count.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = 1) in;
layout(std430, binding = kScanBindingPartials) buffer Partials { uint gPartials[]; };
layout(push_constant) uniform PushBlock { BuildPush gPush; };

void main() {
  uint running = 0u;
  for (uint s = 0u; s < gPush.param; ++s) {
    uint v = gPartials[s];
    gPartials[s] = running;
    running += v;
  }
}
