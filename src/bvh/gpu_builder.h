// Options of the GPU build (bvh.h declares buildGpu with the defaults).
#pragma once
#include <cstdint>
#include <memory>

#include "bvh/bvh.h"
#include "shaders/shared/bvh_build.h"

namespace osr::bvh {

// GpuBuildOptions::treeletRounds' default: two rounds for a scene traversed with exact nodes
// (under kQuantizedTraversalFromTriangles), one above. A small scene builds in milliseconds and
// traces faster for the second round; on large meshes it costs build time for no traversal gain
// (docs/bvh.md, bench/results/bvh.jsonl and trace.jsonl).
inline constexpr uint32_t kTreeletRoundsAuto = ~0u;

// How the hierarchy is made from the sorted triangles. Lbvh: Karras 2012, then treelet
// restructuring (the options below). Ploc: PLOC (shared/bvh_build.h), then one treelet round
// over the upper tree (plocTreeletMinTriangles); for scenes whose arrays fit one storage
// binding. Auto: plocFor's choice.
enum class Hierarchy { Auto, Lbvh, Ploc };

struct GpuBuildOptions {
  Hierarchy hierarchy = Hierarchy::Auto;
  // 0: plain LBVH; kTreeletRoundsAuto: treeletRoundsFor's choice. One round keeps most of the
  // quality on large meshes for a fraction of the build time of more (docs/bvh.md).
  uint32_t treeletRounds = kTreeletRoundsAuto;
  // Round r restructures the nodes with at least treeletMinTriangles << r triangles. The default
  // restructures every node that can hold a full treelet: skipping the small ones saves build
  // time but loses most of the SAH gain (docs/bvh.md, bench/results/bvh.jsonl).
  uint32_t treeletMinTriangles = gpu::bvh_build::kTreeletMaxLeaves;
  // 3..7. 6 rather than 7: a third less restructuring time for a slightly higher SAH
  // (docs/bvh.md, bench/results/bvh.jsonl).
  uint32_t treeletLeaves = 6;
  // After PLOC, one treelet round over the nodes of at least this many triangles (0: none).
  // PLOC's greedy merges leave its upper tree weakest, and it traced coherent rays slower than
  // the LBVH + treelets tree until that round (docs/bvh.md, bench/results/trace.jsonl).
  uint32_t plocTreeletMinTriangles = 512;
  // Rounds of bvh_ploc_local before PLOC's global iterations, each halving the clusters by
  // merges within chunks of 8 in Morton order, in registers (where the device has subgroup
  // shuffles). None by default: on lavapipe a round builds faster but its tree traces slower, and
  // a render traces far more rays than it builds (docs/bvh.md). On GPUs, where shuffles are
  // cheap, it may pay: measure with osr-bench bvh and trace --ploc-local-rounds.
  uint32_t plocLocalRounds = 0;
  // PLOC's global iterations stop at this many clusters or fewer, and bvh_ploc_tail, one
  // workgroup, runs the rest in one dispatch (0: none; at most kPlocTailCapacity): the last
  // iterations cost several dispatches each for few merges. PLOC as a whole was fastest with
  // the tail from 1024-2048 clusters (osr-bench bvh --ploc-tail-clusters; docs/bvh.md).
  uint32_t plocTailClusters = 1024;
};

// The treelet rounds a build of `triangleCount` triangles runs with `options` (before the
// fallback to none for a tree past kBvhMaxDepth).
inline uint32_t treeletRoundsFor(const GpuBuildOptions& options, uint32_t triangleCount) {
  if (options.treeletRounds != kTreeletRoundsAuto) return options.treeletRounds;
  return quantizedTraversal(triangleCount) ? 1u : 2u;
}

// Whether a build of `triangleCount` triangles with `options` makes its hierarchy by PLOC (when
// `fitsOneBinding`: no build array past maxStorageBufferRange). Auto: from kPlocFromTriangles,
// where PLOC starts to build faster than LBVH + treelets, with trees that trace alike
// (osr-bench bvh --hierarchy; docs/bvh.md, bench/results/bvh.jsonl).
inline constexpr uint32_t kPlocFromTriangles = 500000;
inline bool plocFor(const GpuBuildOptions& options, uint32_t triangleCount, bool fitsOneBinding) {
  if (triangleCount < 2 || !fitsOneBinding) return false;
  if (options.hierarchy != Hierarchy::Auto) return options.hierarchy == Hierarchy::Ploc;
  return triangleCount >= kPlocFromTriangles;
}

// Which node arrays a build writes. Traversed: only the one traversal reads
// (quantizedTraversal); the other keeps one node of memory, unwritten, so a quantized scene's
// BVH takes 80 bytes per triangle instead of 144, and bvh_emit_nodes skips the unread exact
// nodes, a large part of its time (docs/bvh.md). Both: also the other, for bvh::download
// (statistics, invariant checks, the host tracer read the exact nodes) and for tests that
// compare the forms.
enum class NodeForms { Traversed, Both };

Bvh buildGpu(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
             uint32_t triangleCount, const GpuBuildOptions& options, BuildStats* stats = nullptr,
             NodeForms forms = NodeForms::Traversed);

struct BuildPasses;     // gpu_builder.cpp: the passes, for one way of reaching the arrays
struct BuildResources;  // gpu_builder.cpp: one build's buffers and views
struct BuildScratch;    // build_scratch.h: the scratch buffers of a build, and of its PLOC
struct PlocScratch;

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
  std::unique_ptr<BuildPasses> passes_;  // arrays in storage bindings
  // Arrays by device address (scenes past one binding), made on first need.
  mutable std::unique_ptr<BuildPasses> addressPasses_;
  mutable std::unique_ptr<BuildScratch> scratch_;
  mutable std::unique_ptr<PlocScratch> plocScratch_;  // made on the first PLOC build
};

}  // namespace osr::bvh
