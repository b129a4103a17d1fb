// What the passes of the GPU BVH build share (shaders/bvh_*.comp; order and data in
// shaders/shared/bvh_build.h, one class per pass in src/bvh/<pass>.h). Each pass owns its
// pipeline and records bind + dispatch + barrier; src/bvh/gpu_builder.cpp strings them together.
// Passes that touch the large arrays (BuildArrays in shared/bvh_build.h) take them as one
// BuildArrayBuffers and are built for one way of reaching them: bindings, or device addresses
// (byAddress) for arrays past maxStorageBufferRange (then caps().bufferDeviceAddress must hold).
#pragma once
#include <vulkan/vulkan.h>

#include <initializer_list>
#include <vector>

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
  vk::BufferRange triangles;       // scene Triangle[triangleCount]
  vk::BufferRange vertices;        // scene Vertex[]
  vk::BufferRange prims;           // BvhLeafTriangle[triangleCount]
  vk::BufferRange interior;        // BvhBuildNode[triangleCount - 1]
  vk::BufferRange leaves;          // BvhBuildNode[triangleCount]
  vk::BufferRange nodes;           // BvhNode[triangleCount - 1] (or 1 where not written)
  vk::BufferRange leafTriangles;   // BvhLeafTriangle[triangleCount]
  vk::BufferRange traversalNodes;  // BvhTraversalNode[triangleCount - 1] (or 1 where not written)
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
// The passes' common layouts, specializations, bindings and dispatch shapes (for the pass
// implementations in src/bvh, not for their callers).
namespace detail {

namespace bb = gpu::bvh_build;
using bb::BuildPush;

// A climbing pass's spec constants (fences, array access, and the treelet size where not 0).
std::vector<vk::SpecConstant> climbSpec(const vk::Context& ctx, bool byAddress,
                                        uint32_t treeletLeaves);
std::vector<vk::SpecConstant> arraySpec(bool byAddress);
// Workgroups of kWorkgroupSize for `items` invocations (at least one group).
uint32_t groups(uint64_t items);
// One invocation per item in rows of at most kMaxGroupsX groups (bvhBuildItem in GLSL), with
// as few groups past `items` as the row count allows.
void dispatchItems(const vk::ComputePipeline& p, VkCommandBuffer cmd, uint64_t items);
BuildPush push(uint32_t triangleCount, uint32_t param);
// Sets the array slots and returns the push block for (triangleCount, param). By address, the
// push block carries the addresses and each slot only the first maxStorageBufferRange bytes of
// its array (the shader reads none of it); a slot whose array the pass does not use (unset)
// takes another array's range.
BuildPush bindArrays(vk::Binder& binder, const ArrayAccess& access, const BuildArrayBuffers& a,
                     uint32_t triangleCount, uint32_t param);
// Storage-buffer slots but for uniform texel buffers at `texelSlots`.
std::vector<VkDescriptorType> storageAndTexelTypes(uint32_t bindingCount,
                                                   std::initializer_list<uint32_t> texelSlots);
// Storage-buffer slots but for the kBuildTexelBindingCount texel slots from `texelBase`.
std::vector<VkDescriptorType> texelTypes(uint32_t bindingCount, uint32_t texelBase);
// `spec` plus kBuildSpecTexels: texel reads where a view reaches as far as the largest array
// read (BvhBuildNode[N]) can be, one binding's worth or, by address, the triangle limit's.
std::vector<vk::SpecConstant> texelSpec(const vk::Context& ctx, bool byAddress,
                                        std::vector<vk::SpecConstant> spec);
// Whether an R32UI view reaches as far as a binding of the 4-byte-per-item arrays (keys, slots)
// can (triangleLimit bounds them by maxStorageBufferRange): 128M texels on lavapipe against 32M.
bool wordTexelsCoverBindings(const vk::Context& ctx);
// The layout and spec of a pass that also reads one array of 4-byte items (keys, slots) through
// an R32UI view at binding `wordTexels`, switched by spec constant `wordSpec`.
std::vector<VkDescriptorType> wordTexelTypes(uint32_t bindingCount, uint32_t texelBase,
                                             uint32_t wordTexels);
std::vector<vk::SpecConstant> wordTexelSpec(const vk::Context& ctx, bool byAddress,
                                            uint32_t wordSpec);
void bindTexels(vk::Binder& binder, uint32_t texelBase, const BuildTexelViews& views);
// A bottom-up climb (lib/bvh_build_nodes.glsl): zeroes the climb counters, binds the arrays,
// texels and counters (beside the pass's own slots already in `binder`) and runs one invocation
// per leaf.
void recordClimb(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, vk::Binder& binder,
                 const ArrayAccess& access, const BuildArrayBuffers& arrays,
                 const BuildTexelViews& texels, uint32_t texelBase, const vk::BufferRange& counters,
                 uint32_t triangleCount);
// One indirect dispatch per level in [first, levels) of a schedule laid out as
// LevelList[levels] then DispatchArgs[levels] (the treelet rounds' by height, the emit's by
// depth), with push.param = the level, each followed by a barrier.
void dispatchLevels(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                    const vk::Binder& binder, BuildPush push, const vk::Buffer& schedule,
                    uint32_t first, uint32_t levels);

}  // namespace detail

}  // namespace osr::bvh
