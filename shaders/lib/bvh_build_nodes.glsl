// The climb of the bottom-up passes (bvh_refit, bvh_treelet, bvh_subtree_count): counters and
// fences, beside the build nodes (lib/bvh_build_arrays.glsl) and their refit
// (lib/bvh_build_refit.glsl).
#ifndef OSR_BVH_BUILD_NODES_GLSL
#define OSR_BVH_BUILD_NODES_GLSL
#include "lib/bvh_build_arrays.glsl"
#include "lib/bvh_build_refit.glsl"

// coherent: see the node arrays in lib/bvh_build_arrays.glsl.
layout(std430, binding = kClimbBindingCounters) coherent buffer Counters { uint gCounters[]; };

// Release the node just written before the counter atomic, acquire the sibling's after it. On
// lavapipe a memory barrier inside divergent control flow stalls the invocations that reach it
// (measured: the climb stopped after one level), and there every atomic is sequentially
// consistent on coherent host memory, so the build specialises the fences away on CPU devices.
layout(constant_id = kClimbSpecFences) const bool kClimbFences = true;
void climbFence() {
  if (kClimbFences) memoryBarrierBuffer();
}

#endif
