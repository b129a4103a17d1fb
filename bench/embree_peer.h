// Embree 3 as the peer of `osr-bench bvh` and `osr-bench trace`, on the same cores in the same
// run: its scene build (the BVH it traces with), a binary BVH from rtcBuildBVH with our SAH
// cost constants whose SAH we evaluate with our formula, and rtcIntersect1 over a ray set.
#pragma once
#ifdef OSR_HAVE_EMBREE
#include <embree3/rtcore.h>

#include <string>
#include <vector>

#include "bvh/synthetic_mesh.h"
#include "shaders/shared/bvh_trace.h"

namespace osr::bench {

class EmbreePeer {
 public:
  EmbreePeer(const bvh::SyntheticMesh& mesh, unsigned threads);
  ~EmbreePeer();
  EmbreePeer(const EmbreePeer&) = delete;
  EmbreePeer& operator=(const EmbreePeer&) = delete;

  // (Re)builds the traceable scene (rtcCommitScene, build quality medium); returns wall ms.
  double buildScene();
  struct BinaryBvh {
    double ms = 0;   // rtcBuildBVH wall time
    double sah = 0;  // under kSahNodeCost / kSahTriangleCost (shaders/shared/bvh.h)
    unsigned depth = 0;
  };
  BinaryBvh buildBinaryBvh() const;
  // Closest hits with rtcIntersect1 on `threads` threads; returns wall ms. Needs buildScene().
  double trace(const std::vector<gpu::bvh_trace::TraceRay>& rays,
               std::vector<gpu::bvh_trace::TraceHit>& hits) const;

 private:
  const bvh::SyntheticMesh& mesh_;
  unsigned threads_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::string error_;
};

}  // namespace osr::bench
#endif
