#version 460
// nn_conv: one convolution layer of the U-Net with its fused epilogue,
//   out[n, co] = bn(act(bias[co] + sum_{ci, ky, kx} w[ci, ky, kx, co] * in[n, ci, y+ky-p, x+kx-p]))
// with zero padding p = kKernel / 2 (3x3 "same" and the final 1x1), act = LeakyReLU / ReLU /
// none and bn = per-channel scale and shift (a BatchNorm that follows the activation in the
// seed's layout, so it cannot fold into this convolution's weights).
// Inputs: in (channel slice view), weights [cin / 4][kKernel^2][coutPadded] x 4 input channels
// (ConvPass::packWeights) as a storage buffer and as texels, params (bias, scale, shift, each
// coutPadded fp32).
// Output: a channel slice view of out (skip concatenations cost no copy); zero outside the
// valid region, so that a tensor stored padded to the tile reads as zero-padded.
//
// Work split: each lane owns one output channel and a kTileH x kTileW pixel tile shared by the
// whole workgroup, accumulated in registers; per input channel it needs the tile's footprint
// (tile plus padding) of that channel, the same for every lane. On GPUs (kShare = 0) each lane
// reads the footprint itself: the addresses are uniform, so the loads are broadcasts. On
// lavapipe (Mesa 22) every storage-buffer access is a loop over the SIMD lanes with a branch
// per lane and component, so uniform loads cost 8x; there (kShare = subgroup size) the lanes
// load different footprint elements and exchange them with subgroupBroadcast, and with
// kInTexel each lane fetches a whole RGBA texel (4 pixels) through a texel buffer, which
// lavapipe compiles to a straight-line gather. fp32 weights come through a texel buffer for
// the same reason (kWeightTexel). No shared memory, no barriers.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "shared/nn.h"
#include "lib/nn_storage.glsl"

layout(constant_id = kSpecWeightHalf) const uint kWeightHalf = 0;
layout(constant_id = kSpecKernel) const int kKernel = 3;
layout(constant_id = kSpecTileH) const int kTileH = 4;
layout(constant_id = kSpecTileW) const int kTileW = 8;
layout(constant_id = kSpecActivation) const uint kActivation = kActLeakyRelu;
layout(constant_id = kSpecBatchNorm) const uint kBatchNorm = 0;
layout(constant_id = kSpecSlope) const float kSlope = 0.2;
layout(constant_id = kSpecShare) const int kShare = 0;
layout(constant_id = kSpecWeightTexel) const uint kWeightTexel = 0;
layout(constant_id = kSpecInTexel) const uint kInTexel = 0;

layout(std430, binding = kBindingWeights) readonly buffer WeightBuf2 { uvec2 gWeights2[]; };
layout(std430, binding = kBindingWeights) readonly buffer WeightBuf4 { uvec4 gWeights4[]; };
layout(std430, binding = kBindingParams) readonly buffer ParamBuf { float gParams[]; };
// The same weights as RGBA32F / RGBA16F texels: lavapipe fetches texels with a straight-line
// gather, several times cheaper than its per-lane loop for a storage-buffer load.
layout(binding = kBindingWeightTexels) uniform samplerBuffer gWeightTexels;
// The input view as texels of 4 consecutive pixels (used with kShare and kInTexel).
layout(binding = kBindingInTexels) uniform samplerBuffer gInTexels;
layout(push_constant) uniform PushBlock { ConvPush gPush; };

// Weights of 4 consecutive input channels for one tap and output channel.
vec4 loadWeight4(uint i) {
  if (kWeightTexel != 0) return texelFetch(gWeightTexels, int(i));
  if (kWeightHalf != 0) {
    const uvec2 w = gWeights2[i];
    return vec4(unpackHalf2x16(w.x), unpackHalf2x16(w.y));
  }
  return uintBitsToFloat(gWeights4[i]);
}

const int kPad = kKernel / 2;
const int kFootW = kTileW + 2 * kPad;
const int kFoot = (kTileH + 2 * kPad) * kFootW;
const int kLanes = kShare > 0 ? kShare : 1;
const int kLoads = (kFoot + kLanes - 1) / kLanes;  // shared loads per input channel per lane
const int kTaps = kKernel * kKernel;
// Texel footprint: rows of kTexW texels starting at column x0 + kTexX0 (one texel of halo
// each side when padding).
const int kTexX0 = kPad > 0 ? -4 : 0;
const int kTexW = kTileW / 4 + (kPad > 0 ? 2 : 0);
const int kTexFoot = (kTileH + 2 * kPad) * kTexW;
const int kTexLoads = (kTexFoot + kLanes - 1) / kLanes;

void main() {
  const uint tile = gl_WorkGroupID.y + gl_WorkGroupID.z * gPush.tileGroupsY;
  if (tile >= gPush.tileCount) return;  // uniform over the workgroup
  const uint co = gl_GlobalInvocationID.x;  // < coutPadded: weights are zero-padded
  const uint height = gPush.height, width = gPush.width, plane = height * width;
  const uint tilesX = width / uint(kTileW), tilesY = height / uint(kTileH);
  const uint n = tile / (tilesX * tilesY);
  const uint rest = tile - n * tilesX * tilesY;
  const int y0 = int(rest / tilesX) * kTileH;
  const int x0 = int(rest % tilesX) * kTileW;

  // Footprint element e = r * kFootW + c is input pixel (y0 + r - pad, x0 + c - pad). With
  // sharing, this lane loads elements lane + k * kShare; `offset` is -1 outside the image.
  int offset[kLoads];
  [[unroll]] for (int k = 0; k < kLoads; ++k) {
    const int e = int(gl_SubgroupInvocationID) + k * kLanes;
    const int iy = y0 + e / kFootW - kPad, ix = x0 + e % kFootW - kPad;
    const bool inside = e < kFoot && iy >= 0 && iy < int(height) && ix >= 0 && ix < int(width);
    offset[k] = inside ? iy * int(width) + ix : -1;
  }

  // The same for texel loads: texel t = lane + k * kShare of the texel footprint.
  int texOffset[kTexLoads];
  [[unroll]] for (int k = 0; k < kTexLoads; ++k) {
    const int t = int(gl_SubgroupInvocationID) + k * kLanes;
    const int iy = y0 + t / kTexW - kPad, ix = x0 + kTexX0 + 4 * (t % kTexW);
    const bool inside = t < kTexFoot && iy >= 0 && iy < int(height) && ix >= 0 && ix < int(width);
    texOffset[k] = inside ? (iy * int(width) + ix) / 4 : -1;
  }

  float acc[kTileH * kTileW];
  [[unroll]] for (int i = 0; i < kTileH * kTileW; ++i) acc[i] = 0.0;

  const uint mapBase = (n * gPush.src.cTotal + gPush.src.c0) * plane;
  const uint groups = (gPush.cin + 3) / 4;
  for (uint g = 0; g < groups; ++g) {
    vec4 w[kTaps];
    [[unroll]] for (int t = 0; t < kTaps; ++t)
      w[t] = loadWeight4((g * uint(kTaps) + uint(t)) * gPush.coutPadded + co);
    [[unroll]] for (int sub = 0; sub < 4; ++sub) {
      // Padding channels of the last group have zero weights; read a real channel instead
      // of past the view so that no NaN from foreign memory meets the zero.
      const uint chanBase = mapBase + min(g * 4 + uint(sub), gPush.cin - 1) * plane;
      float foot[kFoot];
      if (kShare > 0 && kInTexel != 0) {
        vec4 mine[kTexLoads];
        const int texBase = int(chanBase / 4);  // views and planes are 4-pixel aligned
        [[unroll]] for (int k = 0; k < kTexLoads; ++k)
          mine[k] = texOffset[k] >= 0 ? texelFetch(gInTexels, texBase + texOffset[k]) : vec4(0.0);
        [[unroll]] for (int e = 0; e < kFoot; ++e) {
          const int col = e % kFootW - kPad - kTexX0;  // column within the texel row
          const int t = (e / kFootW) * kTexW + col / 4;
          foot[e] = subgroupBroadcast(mine[t / kLanes][col % 4], uint(t % kLanes));
        }
      } else if (kShare > 0) {
        float mine[kLoads];
        [[unroll]] for (int k = 0; k < kLoads; ++k)
          mine[k] = offset[k] >= 0 ? loadIn(chanBase + uint(max(offset[k], 0))) : 0.0;
        [[unroll]] for (int e = 0; e < kFoot; ++e)
          foot[e] = subgroupBroadcast(mine[e / kLanes], uint(e % kLanes));
      } else {
        [[unroll]] for (int e = 0; e < kFoot; ++e) {
          const int iy = y0 + e / kFootW - kPad, ix = x0 + e % kFootW - kPad;
          const bool inside = iy >= 0 && iy < int(height) && ix >= 0 && ix < int(width);
          foot[e] = inside ? loadIn(chanBase + uint(iy) * width + uint(ix)) : 0.0;
        }
      }
      [[unroll]] for (int oy = 0; oy < kTileH; ++oy)
        [[unroll]] for (int ky = 0; ky < kKernel; ++ky)
          [[unroll]] for (int ox = 0; ox < kTileW; ++ox)
            [[unroll]] for (int kx = 0; kx < kKernel; ++kx)
              acc[oy * kTileW + ox] = fma(w[ky * kKernel + kx][sub], foot[(oy + ky) * kFootW + ox + kx],
                                          acc[oy * kTileW + ox]);
    }
  }

  if (co >= gPush.cout) return;
  const float bias = gParams[co];
  const float scale = gParams[gPush.coutPadded + co];
  const float shift = gParams[2 * gPush.coutPadded + co];
  const uint outBase = ((n * gPush.dst.cTotal + gPush.dst.c0 + co) * height + uint(y0)) * width + uint(x0);
  [[unroll]] for (int oy = 0; oy < kTileH; ++oy) {
    [[unroll]] for (int ox = 0; ox < kTileW; ox += 4) {
      const int i = oy * kTileW + ox;
      vec4 v = vec4(acc[i], acc[i + 1], acc[i + 2], acc[i + 3]) + bias;
      if (kActivation == kActLeakyRelu) v = mix(v * kSlope, v, greaterThanEqual(v, vec4(0.0)));
      if (kActivation == kActRelu) v = max(v, vec4(0.0));
      if (kBatchNorm != 0) v = v * scale + shift;
      const bvec4 valid = lessThan(uvec4(x0 + ox) + uvec4(0, 1, 2, 3), uvec4(gPush.validWidth));
      v = uint(y0 + oy) < gPush.validHeight ? mix(vec4(0.0), v, valid) : vec4(0.0);
      storeOut4(outBase + uint(oy) * width + uint(ox), v);
    }
  }
}
