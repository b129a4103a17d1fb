// The GPU BVH build's scratch buffers and their views (GpuBuilder keeps them between builds).
#pragma once
#include <algorithm>
#include <cstdint>

#include "shaders/shared/bvh_build.h"
#include "vk/buffer.h"
#include "vk/buffer_view.h"
#include "vk/context.h"

namespace osr::bvh {

// The build's scratch buffers for up to `capacity` triangles, and their views. A builder keeps
// them for its next build: on a CPU device fresh memory is faulted in on first touch, a large
// part of a first build's CPU time (docs/bvh.md).
struct BuildScratch {
  uint32_t capacity;
  vk::Buffer prims, info, keys, keysTmp, values, valuesTmp, hist, partials, interior, leaves,
      counters, schedule, nodeList;
  // Of keys, values and their scratch twins for the sort; keys (where the sort leaves them) also
  // for bvh_lbvh.
  vk::BufferView keyTexels, valueTexels, keyTmpTexels, valueTmpTexels;
  vk::BufferView interiorTexels, leafTexels, primTexels, slotTexels;
  uint64_t bytes = 0;

  BuildScratch(const vk::Context& ctx, uint32_t n);
};

// PLOC's scratch (PlocPass::Args) for up to `capacity` triangles, kept like BuildScratch.
struct PlocScratch {
  uint32_t capacity;
  vk::Buffer clusters[2], nearest, partials, pairs, state, tail;
  vk::BufferView clusterTexels[2], nearestTexels;
  uint64_t bytes = 0;
  static uint32_t tailCapacity(uint32_t n) {
    return std::min(n, gpu::bvh_build::kPlocTailCapacity);
  }
  PlocScratch(const vk::Context& ctx, uint32_t n);
};

}  // namespace osr::bvh
