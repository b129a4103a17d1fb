#version 460
// bvh_radix_histogram: per chunk of kRadixChunk keys, the count of each 8-bit digit at `shift`,
// written digit-major: hist[digit * chunkCount + chunk]. One invocation per chunk, counters in
// private memory (see shared/bvh_build.h for why). param = shift, param2 = chunkCount.
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh_build.h"

layout(local_size_x = kWorkgroupSize) in;
layout(std430, binding = kRadixBindingKeysIn) readonly buffer Keys { uint gKeys[]; };
layout(std430, binding = kRadixBindingHist) writeonly buffer Hist { uint gHist[]; };
layout(binding = kRadixBindingKeyTexelsIn) uniform usamplerBuffer gKeyTexels;
layout(push_constant) uniform PushBlock { BuildPush gPush; };
layout(constant_id = kRadixSpecTexels) const bool kTexels = false;

uint keyAt(uint i) {
  if (kTexels) return texelFetch(gKeyTexels, int(i)).x;
  return gKeys[i];
}

void main() {
  uint chunk = gl_GlobalInvocationID.x;
  uint chunkCount = gPush.param2;
  if (chunk >= chunkCount) return;
  uint counts[kRadixBins];
  for (uint d = 0u; d < kRadixBins; ++d) counts[d] = 0u;
  uint begin = chunk * kRadixChunk;
  uint end = min(begin + kRadixChunk, gPush.triangleCount);
  for (uint i = begin; i < end; ++i) counts[(keyAt(i) >> gPush.param) & (kRadixBins - 1u)]++;
  for (uint d = 0u; d < kRadixBins; ++d) gHist[d * chunkCount + chunk] = counts[d];
}
