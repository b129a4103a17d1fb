#version 460
// util_fill: data[i] = value for i < count. Inputs: push constants (count, value).
// One invocation per word; used for clearing accumulators and by the Vulkan core's tests.
#extension GL_GOOGLE_include_directive : require
#include "shared/util_fill.h"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kBindingData) writeonly buffer Data { uint gData[]; };
layout(push_constant) uniform PushBlock { Push gPush; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < gPush.count) gData[i] = gPush.value;
}
