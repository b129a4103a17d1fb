// Input and output tensors of the U-Net passes: fp32, or fp16 packed two per 32-bit word
// (kSpecInHalf / kSpecOutHalf), so one shader serves both precisions without the 16-bit
// storage feature (unpackHalf2x16 works everywhere). Each buffer is also declared as vectors
// of 4 elements (uvec4 for fp32, uvec2 for fp16): lavapipe turns every storage-buffer load
// or store instruction into a loop over the SIMD lanes, so one 4-element access costs about
// what a scalar one does. Requires shared/nn.h.
#ifndef OSR_LIB_NN_STORAGE_GLSL
#define OSR_LIB_NN_STORAGE_GLSL

layout(local_size_x_id = kSpecWorkgroup) in;
layout(constant_id = kSpecInHalf) const uint kInHalf = 0;
layout(constant_id = kSpecOutHalf) const uint kOutHalf = 0;

layout(std430, binding = kBindingIn) readonly buffer InBuf { uint gIn[]; };
layout(std430, binding = kBindingIn) readonly buffer InBuf2 { uvec2 gIn2[]; };
layout(std430, binding = kBindingIn) readonly buffer InBuf4 { uvec4 gIn4[]; };
layout(std430, binding = kBindingOut) writeonly buffer OutBuf { uint gOut[]; };
layout(std430, binding = kBindingOut) writeonly buffer OutBuf2 { uvec2 gOut2[]; };
layout(std430, binding = kBindingOut) writeonly buffer OutBuf4 { uvec4 gOut4[]; };

float loadIn(uint i) {
  if (kInHalf != 0) return unpackHalf2x16(gIn[i >> 1])[i & 1u];
  return uintBitsToFloat(gIn[i]);
}

// Elements i .. i + 3; i is a multiple of 4.
vec4 loadIn4(uint i) {
  if (kInHalf != 0) {
    const uvec2 w = gIn2[i >> 2];
    return vec4(unpackHalf2x16(w.x), unpackHalf2x16(w.y));
  }
  return uintBitsToFloat(gIn4[i >> 2]);
}

// Stores elements i and i + 1; i is even.
void storeOutPair(uint i, float a, float b) {
  if (kOutHalf != 0) {
    gOut[i >> 1] = packHalf2x16(vec2(a, b));
  } else {
    gOut[i] = floatBitsToUint(a);
    gOut[i + 1] = floatBitsToUint(b);
  }
}

// Stores elements i .. i + 3; i is a multiple of 4.
void storeOut4(uint i, vec4 v) {
  if (kOutHalf != 0)
    gOut2[i >> 2] = uvec2(packHalf2x16(v.xy), packHalf2x16(v.zw));
  else
    gOut4[i >> 2] = floatBitsToUint(v);
}

#endif
