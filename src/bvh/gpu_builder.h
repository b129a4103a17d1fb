// Options of the GPU build (bvh.h declares buildGpu with the defaults).
#pragma once
#include <cstdint>
#include <memory>

#include "bvh/bvh.h"
#include "shaders/shared/bvh_build.h"

namespace osr::bvh {

// GpuBuildOptions::treeletRounds' default: two rounds for a scene traversed with exact nodes
// (under kQuantizedTraversalFromTriangles; it builds in a few milliseconds), one above. Measured
// on lavapipe (docs/bvh.md): the second round lowers SAH/CPU-SAH from 0.987 to 0.928 on room
// and from 0.990 to 0.928 on cornell, and one-ray incoherent traversal gains 6-7% there (more
// rounds: no further gain). On the 100K and 1.05M-triangle spheres it lowers SAH by 1.3% and
// 1.0% for 16% and 13% more build time, with no measurable traversal gain.
inline constexpr uint32_t kTreeletRoundsAuto = ~0u;

// How the hierarchy is made from the sorted triangles. Lbvh: Karras 2012, then treelet
// restructuring (the options below). Ploc: PLOC (shared/bvh_build.h), then one treelet round
// over the upper tree (plocTreeletMinTriangles); for scenes whose arrays fit one storage
// binding. Auto: plocFor's choice.
enum class Hierarchy { Auto, Lbvh, Ploc };

struct GpuBuildOptions {
  Hierarchy hierarchy = Hierarchy::Auto;
  // 0: plain LBVH; kTreeletRoundsAuto: treeletRoundsFor's choice. One round keeps most of the
  // quality on large meshes: on the 1.05M-triangle bench mesh SAH/CPU-SAH is 1.047 with one
  // round vs 1.033 with three (7-leaf treelets), for less than half of the build time on
  // lavapipe.
  uint32_t treeletRounds = kTreeletRoundsAuto;
  // Round r restructures the nodes with at least treeletMinTriangles << r triangles. Measured on
  // the 1.05M-triangle bench mesh (lavapipe): 14 halves the restructuring time (577 -> ~250 ms)
  // but SAH/CPU-SAH rises from 1.047 to 1.066 and a small mesh gains under 5% over the plain
  // LBVH, so the default restructures every node that can hold a full treelet.
  uint32_t treeletMinTriangles = gpu::bvh_build::kTreeletMaxLeaves;
  // 3..7. 6 rather than 7 (measured on the 1.05M-triangle bench mesh, lavapipe): a third less
  // restructuring time (444 -> 275 ms), SAH/CPU-SAH 1.056 instead of 1.047.
  uint32_t treeletLeaves = 6;
  // After PLOC, one treelet round over the nodes of at least this many triangles (0: none).
  // PLOC's tree alone traced coherent rays 8% slower than the LBVH + treelets tree on the
  // 1.05M-triangle bench mesh at about the same SAH; restructuring its upper nodes (SAH/CPU-SAH
  // 1.073 -> 1.066, about 10 ms) closes that
  // (docs/bvh.md, "Sixth session").
  uint32_t plocTreeletMinTriangles = 512;
  // Rounds of bvh_ploc_local before PLOC's global iterations, each halving the clusters by
  // merges within chunks of 8 in Morton order, in registers (where the device has subgroup
  // shuffles). None by default: on lavapipe one round built the 1M-triangle bench mesh 15-20 ms
  // faster (PLOC 157 -> 38 + 105 ms) but its tree (SAH/CPU-SAH 1.063 -> 1.076) traced primary
  // rays about 9% and diffuse rays 1-12% slower, and a render traces far more rays than it builds
  // (docs/bvh.md, "Eighth session"). On GPUs, where shuffles are cheap, it may pay: measure with
  // osr-bench bvh and trace --ploc-local-rounds.
  uint32_t plocLocalRounds = 0;
  // PLOC's global iterations stop at this many clusters or fewer, and bvh_ploc_tail, one
  // workgroup, runs the rest in one dispatch (0: none; at most kPlocTailCapacity). The
  // 1M-triangle bench mesh is down to 1024 clusters after about 25 of its 80 iterations; the
  // other 55 took 5 dispatches each for a few hundred merges. On lavapipe (osr-bench bvh
  // --ploc-tail-clusters, alternating runs; docs/bvh.md, "Ninth session") the tail takes 2.5 ms
  // from 1024 clusters, 3.6 from 2048, 5.5 from 4096 and 17 from 16384, and PLOC as a whole
  // (iterations and tail) was fastest from 1024-2048.
  uint32_t plocTailClusters = 1024;
};

// The treelet rounds a build of `triangleCount` triangles runs with `options` (before the
// fallback to none for a tree past kBvhMaxDepth).
inline uint32_t treeletRoundsFor(const GpuBuildOptions& options, uint32_t triangleCount) {
  if (options.treeletRounds != kTreeletRoundsAuto) return options.treeletRounds;
  return quantizedTraversal(triangleCount) ? 1u : 2u;
}

// Whether a build of `triangleCount` triangles with `options` makes its hierarchy by PLOC (when
// `fitsOneBinding`: no build array past maxStorageBufferRange). Auto: from kPlocFromTriangles.
// Measured on lavapipe (osr-bench bvh --hierarchy, alternating runs; docs/bvh.md, "Sixth
// session"): PLOC built the 1.05M-triangle bench mesh 12% faster than LBVH + treelets (402-435
// against 472-480 ms), a 500K sphere 3% faster, 250K within noise and 100K 5% slower; the
// trees trace alike.
inline constexpr uint32_t kPlocFromTriangles = 500000;
inline bool plocFor(const GpuBuildOptions& options, uint32_t triangleCount, bool fitsOneBinding) {
  if (triangleCount < 2 || !fitsOneBinding) return false;
  if (options.hierarchy != Hierarchy::Auto) return options.hierarchy == Hierarchy::Ploc;
  return triangleCount >= kPlocFromTriangles;
}

// Which node arrays a build writes. Traversed: only the one traversal reads
// (quantizedTraversal); the other keeps one node of memory, unwritten, so a quantized scene's
// BVH takes 80 bytes per triangle instead of 144, and writing the unread 64-byte exact nodes was
// about a third of bvh_emit_nodes on the 1M-triangle mesh (docs/bvh.md). Both: also the other,
// for bvh::download (statistics, invariant checks, the host tracer read the exact nodes) and for
// tests that compare the forms.
enum class NodeForms { Traversed, Both };

Bvh buildGpu(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
             uint32_t triangleCount, const GpuBuildOptions& options, BuildStats* stats = nullptr,
             NodeForms forms = NodeForms::Traversed);

struct BuildPasses;   // gpu_builder.cpp: the passes, for one way of reaching the arrays
struct BuildScratch;  // the scratch buffers of a build, and of its PLOC
struct PlocScratch;
struct BuildResources;

// Keeps the build's pipelines between builds (creating them compiles every pass, which on
// lavapipe costs far more than building a small scene), and its scratch buffers, sized for the
// largest scene built so far (fresh memory costs page faults on a CPU device). Same contract as
// buildGpu.
class GpuBuilder {
 public:
  explicit GpuBuilder(const vk::Context& ctx, const GpuBuildOptions& options = {});
  ~GpuBuilder();
  GpuBuilder(const GpuBuilder&) = delete;
  GpuBuilder& operator=(const GpuBuilder&) = delete;
  Bvh build(const vk::Buffer& vertices, const vk::Buffer& triangles, uint32_t triangleCount,
            BuildStats* stats = nullptr, NodeForms forms = NodeForms::Traversed) const;

 private:
  // The buffers, views and passes of a build of `triangleCount` triangles; the scratch stays
  // with the builder for its next build.
  std::unique_ptr<BuildResources> allocate(const vk::Buffer& vertices, const vk::Buffer& triangles,
                                           uint32_t triangleCount, NodeForms forms) const;
  const vk::Context& ctx_;
  GpuBuildOptions options_;
  std::unique_ptr<BuildPasses> passes_;                 // arrays in storage bindings
  mutable std::unique_ptr<BuildPasses> addressPasses_;  // arrays by device address (scenes past one binding)
  mutable std::unique_ptr<BuildScratch> scratch_;
  mutable std::unique_ptr<PlocScratch> plocScratch_;  // made on the first PLOC build
};

}  // namespace osr::bvh
