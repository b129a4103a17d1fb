// CPU twin of bvhClosestHit (shaders/lib/bvh_traverse.glsl) over a host tree: the same
// watertight triangle test and conservative box test, for verifying GPU traversal on scenes
// too large for a brute-force loop (benchmarks).
#pragma once
#include <vector>

#include "bvh/cpu_builder.h"
#include "shaders/shared/bvh.h"
#include "shaders/shared/bvh_trace.h"

namespace osr::bvh {

class HostTracer {
 public:
  // `leaves` in the order of tree.leafTriangles (makeLeafTriangles). Both must outlive this.
  HostTracer(const HostBvh& tree, const std::vector<gpu::bvh::BvhLeafTriangle>& leaves)
      : tree_(tree), leaves_(leaves) {}
  gpu::bvh_trace::TraceHit closest(const gpu::bvh_trace::TraceRay& ray) const;

 private:
  const HostBvh& tree_;
  const std::vector<gpu::bvh::BvhLeafTriangle>& leaves_;
};

}  // namespace osr::bvh
