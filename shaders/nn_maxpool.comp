#version 460
// nn_maxpool: 2x2 max-pool with stride 2 (PyTorch MaxPool2d(2)) from one channel-slice view
// into another. Each invocation writes two adjacent output pixels (one packed fp16 word);
// outputs outside the valid region (half the valid input) are stored as zero.
#extension GL_GOOGLE_include_directive : require
#include "shared/nn.h"
#include "lib/nn_storage.glsl"

layout(push_constant) uniform PushBlock { PoolPush gPush; };

void main() {
  const uint p = (gl_WorkGroupID.x + gl_WorkGroupID.y * gPush.groupsX) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  if (p >= gPush.pairCount) return;
  const uint inW = gPush.inWidth, outW = gPush.outWidth, outH = gPush.outHeight;
  const uint ox = (p % (outW / 2)) * 2;
  uint q = p / (outW / 2);
  const uint oy = q % outH;
  q /= outH;
  const uint c = q % gPush.channels, n = q / gPush.channels;
  const uint i = ((n * gPush.src.cTotal + gPush.src.c0 + c) * gPush.inHeight + 2 * oy) * inW + 2 * ox;
  float v[2];
  for (uint k = 0; k < 2; ++k) {
    const uint j = i + 2 * k;
    const bool valid = oy < gPush.validInHeight / 2 && ox + k < gPush.validInWidth / 2;
    v[k] = valid ? max(max(loadIn(j), loadIn(j + 1)), max(loadIn(j + inW), loadIn(j + inW + 1))) : 0.0;
  }
  storeOutPair(((n * gPush.dst.cTotal + gPush.dst.c0 + c) * outH + oy) * outW + ox, v[0], v[1]);
}
