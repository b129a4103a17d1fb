// The device BVH every ray-tracing pass binds (layout: shaders/shared/bvh.h) and the ways to
// build it: buildGpu (compute passes, the renderer's path) and buildOnHost (the CPU binned-SAH
// reference builder, uploaded to the same layout).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "shaders/shared/bvh.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/buffer_view.h"
#include "vk/context.h"
#include "vk/pipeline.h"
#include "vk/timer.h"

namespace osr::bvh {

struct Bvh {
  // Room for nodeCount nodes, root at 0, depth-first: the device build writes only the first
  // (traversal-node count) of them, and every reader walks from the root. An array the build
  // did not write (has*Nodes false) holds one node.
  vk::Buffer nodes;     // BvhNode[nodeCount]: the exact tree (stats, checks, the host)
  vk::Buffer traversalNodes;  // BvhTraversalNode[nodeCount]: the quantized copy
  vk::Buffer leafData;  // BvhLeafTriangle[triangleCount]: leaves' reordered vertex copies
  vk::BufferView nodeTexels;  // RGBA32UI views of the traversed nodes and leafData (texel-fetch traversal)
  vk::BufferView leafTexels;
  uint32_t nodeCount = 0;
  uint32_t triangleCount = 0;
  // Which node array traversal reads (quantizedTraversal): the texel view and storage slot of
  // the nodes show it, and traversing pipelines are specialised for it (TraversalPipeline).
  bool quantized = false;
  // Which node arrays hold the tree (NodeForms, bvh/gpu_builder.h): the other is one node of
  // memory, unwritten. download() needs the exact nodes, makeTexelViews the traversed form.
  bool hasExactNodes = true;
  bool hasQuantizedNodes = true;
  // The node array traversal reads: traversalNodes where quantized, else nodes.
  const vk::Buffer& traversedNodes() const { return quantized ? traversalNodes : nodes; }
  bool hasTraversedNodes() const { return quantized ? hasQuantizedNodes : hasExactNodes; }

  // Usage the builders give both buffers on top of storage use: traversal may read them as
  // uniform texel buffers (shaders/shared/bvh.h).
  static constexpr VkBufferUsageFlags kExtraUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  // Creates nodeTexels / leafTexels once nodes, traversalNodes and leafData exist and
  // `quantized` is set (both builders call it; tests may switch the format of a tree that has
  // both forms and call it again).
  void makeTexelViews(const vk::Context& ctx);

  // Descriptor types by slot (element kBvhBinding*): a traversing pass places them at its
  // OSR_BVH_BINDING and builds its pipeline with traversalSpec.
  static std::array<VkDescriptorType, gpu::bvh::kBvhBindingCount> descriptorTypes();
  // Sets slots base + kBvhBinding* (base: the pass's OSR_BVH_BINDING). A buffer larger than
  // maxStorageBufferRange fills its storage slot with its first maxStorageBufferRange bytes:
  // traversal then reads it by texel fetch (triangleLimit admits such a BVH only where the
  // texel views cover it), and the storage slot is dead code.
  void bind(vk::Binder& binder, uint32_t base) const;
  uint64_t storageRange = 0;  // the device's maxStorageBufferRange (set by makeTexelViews)
};

// Whether traversal reads the quantized nodes for a scene of `triangleCount` triangles: they
// trace slower while the exact nodes stay in cache and faster on large scenes, where memory
// traffic dominates (osr-bench trace; docs/bvh.md, bench/results/trace.jsonl).
inline constexpr uint32_t kQuantizedTraversalFromTriangles = 16384;
inline bool quantizedTraversal(uint32_t triangleCount) { return triangleCount >= kQuantizedTraversalFromTriangles; }

// How traversal reads the BVH: Auto = texel fetch where every BVH the device can bind fits
// maxTexelBufferElements (texelFetchCovers), storage buffers elsewhere. Tests force either.
enum class Access { Auto, Storage, TexelFetch };
bool texelFetchCovers(const vk::Context& ctx);
// Specialization constant kBvhSpecTexelFetch of a traversing pipeline.
vk::SpecConstant traversalSpec(const vk::Context& ctx, Access access = Access::Auto);

struct BuildStats {
  std::vector<vk::PassTime> passes;  // GPU time per pass, in execution order
  double totalMs = 0;                // GPU build: sum of passes; host build: wall time
  double sahCost = 0;                // under kSahNodeCost / kSahTriangleCost
  uint32_t depth = 0;                // nodes on the longest root-to-leaf path
  uint64_t scratchBytes = 0;         // GPU build: temporary buffers, freed when it returns
  uint32_t treeletRounds = 0;        // GPU build: treelet restructuring rounds run
  uint32_t plocIterations = 0;       // GPU build: PLOC iterations that merged (0: LBVH built it)
  uint32_t plocLocalRounds = 0;      // GPU build: bvh_ploc_local rounds before them
  uint32_t plocTailClusters = 0;     // GPU build: where bvh_ploc_tail took over (0: no tail)
};

// Builds on the device by compute passes from the scene's Vertex and Triangle buffers (world
// space positions; vertex indices in range, as the scene loader guarantees). triangleCount >= 1.
// Throws DeviceError when the scene exceeds triangleLimit(ctx), naming the limit and the size. Compiles the build's pipelines on each call: to build repeatedly, keep a
// GpuBuilder (bvh/gpu_builder.h), which also takes options (treelet rounds and size). Writes
// only the node form traversal reads: bvh::download needs NodeForms::Both (gpu_builder.h).
Bvh buildGpu(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
             uint32_t triangleCount, BuildStats* stats = nullptr);

// Downloads the scene buffers, builds with the CPU binned-SAH builder and uploads the result:
// the quality reference, and a fallback for tools. Same preconditions as buildGpu.
Bvh buildOnHost(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
                uint32_t triangleCount, BuildStats* stats = nullptr);

// Largest triangle count the device can build and trace, and the device limit that sets it
// (e.g. "maxMemoryAllocationSize 2048 MiB / 64-byte BVH nodes").
struct TriangleLimit {
  uint32_t triangles = 0;
  std::string limit;
};
TriangleLimit triangleLimit(const vk::Context& ctx);
uint32_t maxTriangles(const vk::Context& ctx);

}  // namespace osr::bvh
