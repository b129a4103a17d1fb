#version 460
// nn_conv: one convolution layer of the U-Net with its fused epilogue,
//   out[n, co] = bn(act(bias[co] + sum_{ci, ky, kx} w[ci, ky, kx, co] * in[n, ci, y+ky-p, x+kx-p]))
// with zero padding p = kKernel / 2 (3x3 "same" and the final 1x1), act = LeakyReLU / ReLU /
// none and bn = per-channel scale and shift (a BatchNorm that follows the activation in the
// seed's layout, so it cannot fold into this convolution's weights).
// Inputs: in (channel slice view), weights [cin][kKernel^2][coutPadded], params (bias, scale,
// shift, each coutPadded fp32). Output: a channel slice view of out (skip concatenation).
// Work split, chosen for CPU Vulkan (lavapipe runs the invocations of a subgroup as SIMD
// lanes): each lane owns one output channel and a kTileH x kTileW pixel tile that is the
// same for the whole workgroup, so every input load has a uniform address (one scalar load
// and a broadcast) and is reused kKernel^2 times per channel; the only per-lane loads are the
// kKernel^2 weights per input channel, amortised over the whole tile. No shared memory and no
// barriers. On GPUs the same split reads weights coalesced and inputs as broadcasts.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared/nn.h"
#include "lib/nn_storage.glsl"

layout(constant_id = kSpecWeightHalf) const uint kWeightHalf = 0;
layout(constant_id = kSpecKernel) const int kKernel = 3;
layout(constant_id = kSpecTileH) const int kTileH = 4;
layout(constant_id = kSpecTileW) const int kTileW = 8;
layout(constant_id = kSpecActivation) const uint kActivation = kActLeakyRelu;
layout(constant_id = kSpecBatchNorm) const uint kBatchNorm = 0;
layout(constant_id = kSpecSlope) const float kSlope = 0.2;

layout(std430, binding = kBindingWeights) readonly buffer WeightBuf { uint gWeights[]; };
layout(std430, binding = kBindingParams) readonly buffer ParamBuf { float gParams[]; };
layout(push_constant) uniform PushBlock { ConvPush gPush; };

float loadWeight(uint i) {
  if (kWeightHalf != 0) return unpackHalf2x16(gWeights[i >> 1])[i & 1u];
  return uintBitsToFloat(gWeights[i]);
}

void main() {
  const uint tile = gl_WorkGroupID.y + gl_WorkGroupID.z * gPush.tileGroupsY;
  if (tile >= gPush.tileCount) return;
  const uint co = gl_GlobalInvocationID.x;  // < coutPadded: weights are zero-padded
  const uint height = gPush.height, width = gPush.width, plane = height * width;
  const uint tilesX = width / uint(kTileW), tilesY = height / uint(kTileH);
  const uint n = tile / (tilesX * tilesY);
  const uint rest = tile - n * tilesX * tilesY;
  const int y0 = int(rest / tilesX) * kTileH;
  const int x0 = int(rest % tilesX) * kTileW;
  const int pad = kKernel / 2;
  const int rowLen = kTileW + kKernel - 1;

  float acc[kTileH * kTileW];
  [[unroll]] for (int i = 0; i < kTileH * kTileW; ++i) acc[i] = 0.0;

  uint inBase = (n * gPush.src.cTotal + gPush.src.c0) * plane;
  uint wIndex = co;
  const uint tapStride = gPush.coutPadded;
  for (uint ci = 0; ci < gPush.cin; ++ci) {
    float w[kKernel * kKernel];
    [[unroll]] for (int t = 0; t < kKernel * kKernel; ++t)
      w[t] = loadWeight(wIndex + uint(t) * tapStride);
    wIndex += uint(kKernel * kKernel) * tapStride;

    [[unroll]] for (int r = 0; r < kTileH + kKernel - 1; ++r) {
      const int iy = y0 + r - pad;
      if (iy < 0 || iy >= int(height)) continue;  // uniform: the tile is the workgroup's
      const uint rowBase = inBase + uint(iy) * width;
      float row[rowLen];
      [[unroll]] for (int c = 0; c < rowLen; ++c) {
        const int ix = x0 + c - pad;
        // Only the first and last column of a tile can fall into the zero padding.
        if (pad > 0 && (c == 0 || c == rowLen - 1))
          row[c] = (ix >= 0 && ix < int(width)) ? loadIn(rowBase + uint(clamp(ix, 0, int(width) - 1))) : 0.0;
        else
          row[c] = loadIn(rowBase + uint(ix));
      }
      [[unroll]] for (int ky = 0; ky < kKernel; ++ky) {
        const int oy = r - ky;
        if (oy < 0 || oy >= kTileH) continue;
        [[unroll]] for (int ox = 0; ox < kTileW; ++ox)
          [[unroll]] for (int kx = 0; kx < kKernel; ++kx)
            acc[oy * kTileW + ox] = fma(w[ky * kKernel + kx], row[ox + kx], acc[oy * kTileW + ox]);
      }
    }
    inBase += plane;
  }

  if (co >= gPush.cout) return;
  const float bias = gParams[co];
  const float scale = gParams[gPush.coutPadded + co];
  const float shift = gParams[2 * gPush.coutPadded + co];
  const uint outBase = ((n * gPush.dst.cTotal + gPush.dst.c0 + co) * height + uint(y0)) * width + uint(x0);
  [[unroll]] for (int oy = 0; oy < kTileH; ++oy) {
    [[unroll]] for (int ox = 0; ox < kTileW; ox += 2) {
      vec2 v = vec2(acc[oy * kTileW + ox], acc[oy * kTileW + ox + 1]) + bias;
      if (kActivation == kActLeakyRelu) v = mix(v * kSlope, v, greaterThanEqual(v, vec2(0.0)));
      if (kActivation == kActRelu) v = max(v, vec2(0.0));
      if (kBatchNorm != 0) v = v * scale + shift;
      storeOutPair(outBase + uint(oy) * width + uint(ox), v.x, v.y);
    }
  }
}
