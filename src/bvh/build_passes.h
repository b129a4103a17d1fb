// The passes of the GPU BVH build (shaders/bvh_*.comp; order and data in
// shaders/shared/bvh_build.h). Each owns its pipeline and records bind + dispatch + barrier;
// src/bvh/gpu_builder.cpp strings them together. Passes that touch the large arrays
// (BuildArrays in shared/bvh_build.h) take them as one BuildArrayBuffers and are built for one
// way of reaching them: bindings, or device addresses (byAddress) for arrays past
// maxStorageBufferRange (then caps().bufferDeviceAddress must hold).
#pragma once
#include <vulkan/vulkan.h>

#include <optional>

#include "shaders/shared/bvh_build.h"
#include "shaders/shared/scene.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"
#include "vk/timer.h"

namespace osr::bvh {

// The build's large arrays. A pass reads or writes the ones its shader does (see each pass);
// the others may stay unset.
struct BuildArrayBuffers {
  vk::BufferRange triangles;      // scene Triangle[triangleCount]
  vk::BufferRange vertices;       // scene Vertex[]
  vk::BufferRange prims;          // BvhLeafTriangle[triangleCount]
  vk::BufferRange interior;       // BvhBuildNode[triangleCount - 1]
  vk::BufferRange leaves;         // BvhBuildNode[triangleCount]
  vk::BufferRange nodes;          // BvhNode[triangleCount - 1] (or 1 where not written)
  vk::BufferRange leafTriangles;  // BvhLeafTriangle[triangleCount]
  vk::BufferRange traversalNodes; // BvhTraversalNode[triangleCount - 1] (or 1 where not written)
  // Whether some array is past what one binding holds (passes must then be byAddress).
  bool pastOneBinding(const vk::Context& ctx) const;
};

// RGBA32UI views (vk::BufferView::uintTexels) of interior, leaves and prims, for the passes
// that read them by texel fetch (shared/bvh_build.h, "Texel reads"); those buffers need
// kUsage on top of storage use.
struct BuildTexelViews {
  static constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  VkBufferView interior = VK_NULL_HANDLE;
  VkBufferView leaves = VK_NULL_HANDLE;
  VkBufferView prims = VK_NULL_HANDLE;
};

// How a pass reaches the large arrays, fixed when its pipeline is made.
struct ArrayAccess {
  const vk::Context* ctx = nullptr;
  bool byAddress = false;
};

// bvh_bounds: vertex copies per triangle + centroid bounds (info must hold the empty box).
// Arrays: triangles, vertices (in), prims (out).
class BoundsPass {
 public:
  BoundsPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    vk::BufferRange info;  // in/out: BvhBuildInfo
    uint32_t triangleCount = 0;
    // RGBA32UI views of the scene's triangles and vertices (vk::BufferView::uintTexels) that
    // reach every triangle and vertex, or null: then the pass reads the storage arrays.
    VkBufferView triangleTexels = VK_NULL_HANDLE, vertexTexels = VK_NULL_HANDLE;
    VkBufferView unusedTexels = VK_NULL_HANDLE;  // any valid view, bound in their place when null
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  mutable std::optional<vk::ComputePipeline> pipelines_[2];  // by kBoundsSpecSceneTexels, made on first need
};

// bvh_morton: keys = Morton codes of the centroids, values = triangle indices. Arrays: prims
// (through texels).
class MortonPass {
 public:
  MortonPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange info, keys, values;
    uint32_t triangleCount = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

// bvh_scan_reduce + bvh_scan_top + bvh_scan_apply: in-place exclusive scan of uints.
class ExclusiveScan {
 public:
  explicit ExclusiveScan(const vk::Context& ctx);
  static uint64_t partialsBytes(uint32_t count);
  struct Args {
    vk::BufferRange data;      // uint[count], scanned in place
    vk::BufferRange partials;  // scratch: partialsBytes(count)
    uint32_t count = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  vk::ComputePipeline reduce_, top_, apply_;
};

// Stable LSD radix sort of 30-bit keys with uint values: 4 rounds of histogram, scan, scatter.
// The result ends in keys/values (an even number of rounds through the ping-pong buffers).
class RadixSort {
 public:
  explicit RadixSort(const vk::Context& ctx);
  static uint64_t histogramBytes(uint32_t count);
  // Usage keys, values and their scratch twins need on top of storage use (their R32UI views).
  static constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  struct Args {
    vk::BufferRange keys, values;        // in/out
    vk::BufferRange keysTmp, valuesTmp;  // scratch, same sizes
    vk::BufferRange histogram;           // scratch: histogramBytes(count)
    vk::BufferRange partials;            // scratch: ExclusiveScan::partialsBytes(histogram words)
    uint32_t count = 0;
    // R32UI views (vk::BufferView::uintWords) of keys, values, keysTmp, valuesTmp.
    VkBufferView keyTexels = VK_NULL_HANDLE, valueTexels = VK_NULL_HANDLE;
    VkBufferView keyTmpTexels = VK_NULL_HANDLE, valueTmpTexels = VK_NULL_HANDLE;
  };
  // `timer` (may be null) gets scopes "bvh_radix_histogram", "bvh_scan", "bvh_radix_scatter".
  void record(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer = nullptr) const;

 private:
  vk::ComputePipeline histogram_, scatter_;
  ExclusiveScan scan_;
};

// bvh_lbvh: Karras 2012 hierarchy over sorted keys; initialises the leaves. Arrays: prims
// (in, through texels), interior, leaves (out).
class LbvhPass {
 public:
  LbvhPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange keys, values;
    VkBufferView keyTexels = VK_NULL_HANDLE;  // R32UI view of keys (vk::BufferView::uintWords)
    uint32_t triangleCount = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

// bvh_refit: bottom-up bounds, counts, costs, heights; counters are zeroed by record().
// Arrays: interior, leaves (also through texels).
class RefitPass {
 public:
  RefitPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    const vk::Buffer* counters = nullptr;  // uint per interior node
    uint32_t triangleCount = 0;
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

// One round of treelet restructuring: bvh_treelet_count / _plan / _scatter, then bvh_treelet
// once per height with an indirect dispatch (see shared/bvh_build.h). Arrays: interior, leaves
// (bvh_treelet reads them through texels).
class TreeletPass {
 public:
  // treeletLeaves in 3..kTreeletMaxLeaves.
  TreeletPass(const vk::Context& ctx, uint32_t treeletLeaves, bool byAddress);
  static uint64_t scheduleBytes();
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange counters;
    const vk::Buffer* schedule = nullptr;  // scheduleBytes()
    vk::BufferRange nodeList;              // uint per interior node
    uint32_t triangleCount = 0;
    uint32_t minTriangles = 0;             // smallest subtree restructured
    // SubtreeCountPass's counts (uint per interior node) and their R32UI view: kept up to date
    // where countNodes (they are complete before the round: after PlocPass), else unread.
    vk::BufferRange subtreeNodes;
    VkBufferView subtreeNodeTexels = VK_NULL_HANDLE;
    bool countNodes = false;
  };
  // `timer` (may be null) gets scopes "bvh_treelet_schedule" (count, plan, scatter) and
  // "bvh_treelet" (the per-height dispatches).
  void record(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer = nullptr) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline count_, plan_, scatter_, treelet_;
};

// PLOC (shared/bvh_build.h): bvh_ploc_init, Args::localRounds rounds of bvh_ploc_local, then
// `iterations` rounds of bvh_ploc_nearest, _count, _plan, _compact and _merge, which leave the
// tree in interior/leaves as LbvhPass + RefitPass (+ TreeletPass) would.
// Iterations after the last merge dispatch no group; state.count[finalParity] == 1 says the
// tree is complete (else record again with more). Arrays: prims (in, through texels), interior,
// leaves (out); reached through bindings only (scenes within maxStorageBufferRange).
class PlocPass {
 public:
  explicit PlocPass(const vk::Context& ctx);
  static constexpr VkBufferUsageFlags kClusterUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  static constexpr VkBufferUsageFlags kStateUsage =
      VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange values;                       // sorted triangle indices
    const vk::Buffer* clusters[2] = {};           // 32 bytes per triangle, with kClusterUsage
    VkBufferView clusterTexels[2] = {};           // RGBA32UI views of them (how they are read)
    vk::BufferRange nearest;                      // uint per triangle (kClusterUsage)
    vk::BufferRange partials;                     // 2 * (triangleCount + kWorkgroupSize) uints
    vk::BufferRange pairs;                        // uvec4 per 2 triangles
    VkBufferView nearestTexels = VK_NULL_HANDLE;  // R32UI view of nearest
    vk::BufferRange subtreeNodes;                 // out: SubtreeCountPass's counts
    VkBufferView subtreeNodeTexels = VK_NULL_HANDLE;  // R32UI view of them
    const vk::Buffer* state = nullptr;            // PlocState, with kStateUsage
    uint32_t triangleCount = 0;                   // >= 2, <= kWorkgroupSize * kMaxGroupsX
    uint32_t localRounds = 0;                     // bvh_ploc_local rounds (0 where !localMergesSupported)
    // bvh_ploc_tail: the global iterations stop at this many clusters or fewer and the tail
    // finishes (0: no tail, the global iterations run to the root); its scratch, 64 bytes per
    // cluster of tailCapacity (<= kPlocTailCapacity).
    uint32_t tailClusters = 0, tailCapacity = 0;
    vk::BufferRange tailScratch;
  };
  // Whether bvh_ploc_local can run on `ctx`'s device: subgroup shuffles, and chunks that
  // subgroups hold whole.
  static bool localMergesSupported(const vk::Context& ctx);
  // bvh_ploc_init, `localRounds` rounds of bvh_ploc_local, the first `iterations` global
  // iterations, bvh_ploc_tail where args.tailClusters asks, and bvh_ploc_root; `timer` (may be
  // null) gets scopes "bvh_ploc_init", "bvh_ploc_local", "bvh_ploc" and "bvh_ploc_tail".
  void record(VkCommandBuffer cmd, const Args& args, uint32_t iterations, vk::GpuTimer* timer = nullptr) const;
  // The parity of PlocState.count that holds the clusters left after record().
  static uint32_t finalParity(uint32_t localRounds, uint32_t iterations) { return (localRounds + iterations) & 1u; }

 private:
  void recordIterations(VkCommandBuffer cmd, const Args& args, uint32_t iterations, vk::GpuTimer* timer) const;
  void recordLocal(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer) const;
  vk::Binder binder(const vk::ComputePipeline& pipeline, const Args& a, uint32_t in, uint32_t out, uint32_t parity,
                    gpu::bvh_build::BuildPush& push) const;
  ArrayAccess access_;
  vk::ComputePipeline init_, nearest_, count_, plan_, compact_, merge_, tail_, root_;
  std::optional<vk::ComputePipeline> local_;
};

// bvh_subtree_count: traversal nodes per subtree, for the depth-first order of bvh_emit_nodes.
// Arrays: interior, leaves (through texels).
class SubtreeCountPass {
 public:
  SubtreeCountPass(const vk::Context& ctx, bool byAddress);
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange counters;      // scratch: uint per interior node (zeroed here)
    vk::BufferRange subtreeNodes;  // out: uint per interior node
    uint32_t triangleCount = 0;    // >= 2
  };
  void record(VkCommandBuffer cmd, const Args& args) const;

 private:
  ArrayAccess access_;
  vk::ComputePipeline pipeline_;
};

// bvh_emit_nodes once per depth (indirect), then bvh_emit_leaves: traversal nodes in depth-first
// order, then leaf triangles (info.leafCounter must be 0). Arrays: interior, leaves, prims (in,
// through texels), nodes, traversalNodes, leafTriangles (out).
class EmitPass {
 public:
  EmitPass(const vk::Context& ctx, bool byAddress);
  static uint64_t scheduleBytes();
  // Usage the slots buffer needs on top of storage use (its R32UI view, slotTexels).
  static constexpr VkBufferUsageFlags kSlotsUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange info;
    vk::BufferRange slots;                     // scratch: uint per interior node
    VkBufferView slotTexels = VK_NULL_HANDLE;  // R32UI view of slots (vk::BufferView::uintWords)
    // Depth-first order (unread for one triangle): SubtreeCountPass's counts; scratch positions,
    // node lists and leaf bases (uint per interior node) and the depth schedule (scheduleBytes()).
    vk::BufferRange subtreeNodes, positions, levelNodes, leafBases;
    const vk::Buffer* schedule = nullptr;
    uint32_t triangleCount = 0;
    bool exactNodes = true, quantizedNodes = true;  // which node arrays to write (Bvh::has*Nodes)
  };
  // `timer` (may be null) gets scopes "bvh_emit_nodes" (all depths) and "bvh_emit_leaves".
  void record(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer = nullptr) const;

 private:
  // bvh_emit_nodes specialized for (forms, one triangle) (shared/bvh_build.h, kEmitSpecForms),
  // made on first need: index forms | single << 2.
  const vk::ComputePipeline& nodes(uint32_t forms, bool singleTriangle) const;
  ArrayAccess access_;
  mutable std::optional<vk::ComputePipeline> nodes_[8];
  vk::ComputePipeline leaves_;
};

}  // namespace osr::bvh
