// Quantization of a BvhNode's child boxes into a BvhTraversalNode (shared/bvh.h), one text for
// the device build (bvh_emit_nodes) and the host (src/bvh/node_quantize.cpp: the CPU builder's
// upload and the tests' reference), so both give the same bits.
//
// Per axis: the origin o is the node box's min rounded down to a float whose low 8 mantissa bits
// are zero; the scale s = 2^e is the smallest with (max - o) / s <= 255 - kBvhQuantizeMargin;
// a child's min plane becomes floor((min - o) / s), its max plane ceil((max - o) / s). The
// difference min - o is rounded to nearest, which can be off by 2^-24 of it, so a quotient
// within kBvhQuantizeMargin of a whole number steps one more quantum outwards: the quantized
// box always contains the exact one, in real arithmetic. Multiplying by 2^-e is exact.
#ifndef OSR_SHARED_BVH_QUANTIZE_H
#define OSR_SHARED_BVH_QUANTIZE_H
#include "shared/bvh.h"

#ifdef __cplusplus
#include <cmath>
#define OSR_QUANTIZE_FN inline
#define OSR_PRECISE
namespace osr::gpu::bvh {
using glm::floatBitsToUint;
using glm::uintBitsToFloat;
inline float floor(float x) { return std::floor(x); }
inline float ceil(float x) { return std::ceil(x); }
}  // namespace osr::gpu::bvh
#else
#define OSR_QUANTIZE_FN
#define OSR_PRECISE precise
#endif

OSR_NAMESPACE_BEGIN(bvh)

OSR_CONST(float, kBvhQuantizeMargin, 1.0f / 1024.0f);

// The largest float <= x whose low 8 mantissa bits are zero (negative: magnitude rounded up).
OSR_QUANTIZE_FN float bvhOriginBelow(float x) {
  uint b = floatBitsToUint(x);
  b = x >= 0.0f ? (b & ~kBvhQuantizeExponentBits) : ((b + kBvhQuantizeExponentBits) & ~kBvhQuantizeExponentBits);
  return uintBitsToFloat(b);
}

// 2^e for e in [-126, 127] as a float.
OSR_QUANTIZE_FN float bvhPow2(int e) { return uintBitsToFloat(uint(e + 127) << 23u); }

// The scale exponent e for extent d = max - o (d >= 0).
OSR_QUANTIZE_FN int bvhQuantizeExponent(float d) {
  int ex = int((floatBitsToUint(d) >> 23u) & 0xffu) - 127;  // d in [2^ex, 2^(ex+1)) when normal
  int e = ex - 7;                                            // d / 2^e in [128, 256)
  if (e < -126) return -126;
  if (d * bvhPow2(-e) > 255.0f - kBvhQuantizeMargin) e += 1;
  return e < -126 ? -126 : (e > 127 ? 127 : e);
}

OSR_QUANTIZE_FN uint bvhQuantizeDown(float v, float o, float invScale) {
  OSR_PRECISE float x = (v - o) * invScale;
  OSR_PRECISE float q = floor(x);
  if (x - q < kBvhQuantizeMargin) q -= 1.0f;
  return uint(q < 0.0f ? 0.0f : (q > 255.0f ? 255.0f : q));
}
OSR_QUANTIZE_FN uint bvhQuantizeUp(float v, float o, float invScale) {
  OSR_PRECISE float x = (v - o) * invScale;
  OSR_PRECISE float q = ceil(x);
  if (q - x < kBvhQuantizeMargin) q += 1.0f;
  return uint(q < 0.0f ? 0.0f : (q > 255.0f ? 255.0f : q));
}

// One axis: x = the frame word (origin bits | exponent byte), y = the four plane bytes
// aLo | aHi << 8 | bLo << 16 | bHi << 24. An absent child gets the empty box (255, 0).
OSR_QUANTIZE_FN uvec2 bvhQuantizeAxis(float aLo, float aHi, float bLo, float bHi, bool hasA, bool hasB) {
  float lo = hasA ? (hasB ? (aLo < bLo ? aLo : bLo) : aLo) : (hasB ? bLo : 0.0f);
  float hi = hasA ? (hasB ? (aHi > bHi ? aHi : bHi) : aHi) : (hasB ? bHi : 0.0f);
  float o = bvhOriginBelow(lo);
  OSR_PRECISE float d = hi - o;
  int e = bvhQuantizeExponent(d > 0.0f ? d : 0.0f);
  float invScale = bvhPow2(-e);  // e <= 122 (an extent that overflows to inf), so -e is in range
  uint qa = hasA ? (bvhQuantizeDown(aLo, o, invScale) | (bvhQuantizeUp(aHi, o, invScale) << 8u)) : 0xffu;
  uint qb = hasB ? (bvhQuantizeDown(bLo, o, invScale) | (bvhQuantizeUp(bHi, o, invScale) << 8u)) : 0xffu;
  return uvec2(floatBitsToUint(o) | uint(e + 127), qa | (qb << 16u));
}

// A child box is present when finite and not inverted (the empty child of shared/bvh.h is
// inverted); nodes that traversal never reaches may hold anything.
OSR_QUANTIZE_FN bool bvhBoxPresent(vec3 lo, vec3 hi) {
  bool ok = true;
  for (int k = 0; k < 3; ++k)
    ok = ok && lo[k] <= hi[k] && lo[k] > -3.0e38f && hi[k] < 3.0e38f;
  return ok;
}

OSR_QUANTIZE_FN BvhTraversalNode bvhQuantizeNode(BvhNode n) {
  bool hasA = bvhBoxPresent(n.aMin, n.aMax), hasB = bvhBoxPresent(n.bMin, n.bMax);
  BvhTraversalNode t;
  t.frame.w = n.a;
  t.boxes.x = n.b;
  for (int k = 0; k < 3; ++k) {
    uvec2 axis = bvhQuantizeAxis(n.aMin[k], n.aMax[k], n.bMin[k], n.bMax[k], hasA, hasB);
    t.frame[k] = axis.x;
    t.boxes[k + 1] = axis.y;
  }
  return t;
}

OSR_NAMESPACE_END
#endif
