// Input and output tensors of the U-Net passes as 32-bit words holding either one fp32 value
// or two packed fp16 values (kSpecInHalf / kSpecOutHalf), so that one shader serves both
// precisions without the 16-bit storage feature: unpackHalf2x16 works on every device.
// Requires shared/nn.h.
#ifndef OSR_LIB_NN_STORAGE_GLSL
#define OSR_LIB_NN_STORAGE_GLSL

layout(local_size_x_id = kSpecWorkgroup) in;
layout(constant_id = kSpecInHalf) const uint kInHalf = 0;
layout(constant_id = kSpecOutHalf) const uint kOutHalf = 0;

layout(std430, binding = kBindingIn) readonly buffer InBuf { uint gIn[]; };
layout(std430, binding = kBindingOut) writeonly buffer OutBuf { uint gOut[]; };

float loadIn(uint i) {
  if (kInHalf != 0) return unpackHalf2x16(gIn[i >> 1])[i & 1u];
  return uintBitsToFloat(gIn[i]);
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

#endif
