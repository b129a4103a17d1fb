// Stage 4 (PLOC hierarchy) of the GPU BVH build: the tree by PLOC merges, and how many
// iterations to record.
#pragma once
#include <vulkan/vulkan.h>

#include <optional>

#include "bvh/build_pass.h"

namespace osr::bvh {

// PLOC (shared/bvh_build.h): bvh_ploc_init, Args::localRounds rounds of bvh_ploc_local, then
// `iterations` rounds of bvh_ploc_nearest, _count, _plan, _compact and _merge, which leave the
// tree in interior/leaves as LbvhPass + RefitPass (+ TreeletPass) would.
// Iterations after the last merge dispatch no group; result() says whether the tree is complete
// and Iterations how many to record again if not. Arrays: prims (in, through texels), interior,
// leaves (out); reached through bindings only (scenes within maxStorageBufferRange).
class PlocPass {
 public:
  explicit PlocPass(const vk::Context& ctx);
  static constexpr VkBufferUsageFlags kClusterUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  static constexpr VkBufferUsageFlags kStateUsage = VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                                    VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  struct Args {
    const BuildArrayBuffers* arrays = nullptr;
    const BuildTexelViews* texels = nullptr;
    vk::BufferRange values;                           // sorted triangle indices
    const vk::Buffer* clusters[2] = {};               // 32 bytes per triangle, with kClusterUsage
    VkBufferView clusterTexels[2] = {};               // RGBA32UI views of them (how they are read)
    vk::BufferRange nearest;                          // uint per triangle (kClusterUsage)
    vk::BufferRange partials;                         // 2 * (triangleCount + kWorkgroupSize) uints
    vk::BufferRange pairs;                            // uvec4 per 2 triangles
    VkBufferView nearestTexels = VK_NULL_HANDLE;      // R32UI view of nearest
    vk::BufferRange subtreeNodes;                     // out: SubtreeCountPass's counts
    VkBufferView subtreeNodeTexels = VK_NULL_HANDLE;  // R32UI view of them
    const vk::Buffer* state = nullptr;                // PlocState, with kStateUsage
    uint32_t triangleCount = 0;                       // >= 2, <= kWorkgroupSize * kMaxGroupsX
    uint32_t localRounds = 0;  // bvh_ploc_local rounds (0 where !localMergesSupported)
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
  void record(VkCommandBuffer cmd, const Args& args, uint32_t iterations,
              vk::GpuTimer* timer = nullptr) const;
  // The parity of PlocState.count that holds the clusters left after record().
  static uint32_t finalParity(uint32_t localRounds, uint32_t iterations) {
    return (localRounds + iterations) & 1u;
  }
  // What a build recorded with `iterations` left in args.state (read after it ran): the clusters
  // left (1: the tree is complete) and the global iterations that merged.
  struct Result {
    uint32_t clustersLeft = 0, iterationsMerged = 0;
  };
  static Result result(const Args& args, uint32_t iterations);

  // How many global iterations a build records. Those past the last merge still cost their
  // dispatches, so the first build records an estimate from the triangle count (and from where
  // the tail takes over), and a build that left more than one cluster is recorded again with
  // twice as many; every iteration merges at least one pair, so triangleCount always suffice.
  class Iterations {
   public:
    Iterations() = default;
    Iterations(uint32_t triangleCount, uint32_t tailClusters);
    uint32_t count() const { return count_; }
    // After a build that recorded count() iterations left `clustersLeft`: whether the tree is
    // complete; if not, count() grows for the next build. Throws DeviceError where count() had
    // reached triangleCount.
    bool complete(uint32_t clustersLeft);

   private:
    uint32_t triangleCount_ = 0, count_ = 0;
  };

 private:
  void recordIterations(VkCommandBuffer cmd, const Args& args, uint32_t iterations,
                        vk::GpuTimer* timer) const;
  void recordLocal(VkCommandBuffer cmd, const Args& args, vk::GpuTimer* timer) const;
  vk::Binder binder(const vk::ComputePipeline& pipeline, const Args& a, uint32_t in, uint32_t out,
                    uint32_t parity, gpu::bvh_build::BuildPush& push) const;
  ArrayAccess access_;
  vk::ComputePipeline init_, nearest_, count_, plan_, compact_, merge_, tail_, root_;
  std::optional<vk::ComputePipeline> local_;
};

}  // namespace osr::bvh
