#version 460
// bvh_radix_scatter: moves each key/value pair of a chunk to its digit's next slot, starting
// from the chunk's scanned histogram offsets; keys of a chunk are visited in order, so the sort
// is stable (LSD radix sort needs that). param = shift, param2 = chunkCount.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kRadixBindingKeysIn) readonly buffer KeysIn { uint gKeysIn[]; };
layout(std430, binding = kRadixBindingValuesIn) readonly buffer ValuesIn { uint gValuesIn[]; };
layout(std430, binding = kRadixBindingHist) readonly buffer Hist { uint gHist[]; };
layout(std430, binding = kRadixBindingKeysOut) writeonly buffer KeysOut { uint gKeysOut[]; };
layout(std430, binding = kRadixBindingValuesOut) writeonly buffer ValuesOut { uint gValuesOut[]; };
layout(binding = kRadixBindingKeyTexelsIn) uniform usamplerBuffer gKeyTexels;
layout(binding = kRadixBindingValueTexelsIn) uniform usamplerBuffer gValueTexels;
layout(push_constant) uniform PushBlock { BuildPush gPush; };
layout(constant_id = kRadixSpecTexels) const bool kTexels = false;

uint keyAt(uint i) {
  if (kTexels) return texelFetch(gKeyTexels, int(i)).x;
  return gKeysIn[i];
}
uint valueAt(uint i) {
  if (kTexels) return texelFetch(gValueTexels, int(i)).x;
  return gValuesIn[i];
}

void main() {
  uint chunk = gl_GlobalInvocationID.x;
  uint chunkCount = gPush.param2;
  if (chunk >= chunkCount) return;
  uint offsets[kRadixBins];
  for (uint d = 0u; d < kRadixBins; ++d) offsets[d] = gHist[d * chunkCount + chunk];
  uint begin = chunk * kRadixChunk;
  uint end = min(begin + kRadixChunk, gPush.triangleCount);
  for (uint i = begin; i < end; ++i) {
    uint key = keyAt(i);
    uint pos = offsets[(key >> gPush.param) & (kRadixBins - 1u)]++;
    gKeysOut[pos] = key;
    gValuesOut[pos] = valueAt(i);
  }
}
