#version 460
// nn_upsample: bilinear x2 upsampling as PyTorch's Upsample(scale_factor=2, mode="bilinear",
// align_corners=False): source coordinate (dst + 0.5) / 2 - 0.5 clamped below at 0, the upper
// neighbour clamped to the edge, and PyTorch's order of the weighted sum. Writes a channel
// slice of the next layer's input, which is how the decoder's concatenation costs no copy.
// Sizes are the valid input region's (clamping there); outputs outside twice it are zero.
#extension GL_GOOGLE_include_directive : require
#include "shared/nn.h"
#include "lib/nn_storage.glsl"

layout(push_constant) uniform PushBlock { PoolPush gPush; };

// Lower source index, upper source index and the upper weight for one axis.
void source(uint dst, uint inSize, out uint i0, out uint i1, out float l1) {
  const float s = max((float(dst) + 0.5) * 0.5 - 0.5, 0.0);
  i0 = uint(s);
  i1 = min(i0 + 1, inSize - 1);
  l1 = s - float(i0);
}

void main() {
  const uint p = (gl_WorkGroupID.x + gl_WorkGroupID.y * gPush.groupsX) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  if (p >= gPush.pairCount) return;
  const uint inW = gPush.inWidth, outW = gPush.outWidth, outH = gPush.outHeight;
  const uint validH = gPush.validInHeight, validW = gPush.validInWidth;
  const uint ox = (p % (outW / 2)) * 2;
  uint q = p / (outW / 2);
  const uint oy = q % outH;
  q /= outH;
  const uint c = q % gPush.channels, n = q / gPush.channels;
  const uint base = (n * gPush.src.cTotal + gPush.src.c0 + c) * gPush.inHeight * inW;
  uint y0, y1;
  float ly1;
  source(min(oy, 2 * validH - 1), validH, y0, y1, ly1);
  const float ly0 = 1.0 - ly1;
  float v[2];
  for (uint k = 0; k < 2; ++k) {
    uint x0, x1;
    float lx1;
    source(min(ox + k, 2 * validW - 1), validW, x0, x1, lx1);
    const float lx0 = 1.0 - lx1;
    const float top = lx0 * loadIn(base + y0 * inW + x0) + lx1 * loadIn(base + y0 * inW + x1);
    const float bottom = lx0 * loadIn(base + y1 * inW + x0) + lx1 * loadIn(base + y1 * inW + x1);
    v[k] = oy < 2 * validH && ox + k < 2 * validW ? ly0 * top + ly1 * bottom : 0.0;
  }
  storeOutPair(((n * gPush.dst.cTotal + gPush.dst.c0 + c) * outH + oy) * outW + ox, v[0], v[1]);
}
