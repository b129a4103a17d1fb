#include "bvh/build_pass.h"

#include <algorithm>
#include <array>
#include <cstddef>

#include "bvh/bvh.h"
#include "common/error.h"

namespace osr::bvh {

using namespace detail;

namespace {

// The arrays in slot order (kBuildBinding*).
std::array<vk::BufferRange, bb::kBuildArrayBindingCount> slots(const BuildArrayBuffers& a) {
  std::array<vk::BufferRange, bb::kBuildArrayBindingCount> s;
  s[bb::kBuildBindingTriangles] = a.triangles;
  s[bb::kBuildBindingVertices] = a.vertices;
  s[bb::kBuildBindingPrims] = a.prims;
  s[bb::kBuildBindingInterior] = a.interior;
  s[bb::kBuildBindingLeaves] = a.leaves;
  s[bb::kBuildBindingNodes] = a.nodes;
  s[bb::kBuildBindingLeafTriangles] = a.leafTriangles;
  s[bb::kBuildBindingTraversalNodes] = a.traversalNodes;
  return s;
}

}  // namespace

namespace detail {

// See climbFence() in shaders/lib/bvh_build_nodes.glsl for why CPU devices run without fences.
std::vector<vk::SpecConstant> climbSpec(const vk::Context& ctx, bool byAddress,
                                        uint32_t treeletLeaves) {
  std::vector<vk::SpecConstant> spec = {
      vk::specUint(bb::kClimbSpecFences, ctx.caps().isCpu() ? 0u : 1u),
      vk::specUint(bb::kBuildSpecByAddress, byAddress ? 1u : 0u)};
  if (treeletLeaves) spec.push_back(vk::specUint(bb::kTreeletSpecLeaves, treeletLeaves));
  return spec;
}

std::vector<vk::SpecConstant> arraySpec(bool byAddress) {
  return {vk::specUint(bb::kBuildSpecByAddress, byAddress ? 1u : 0u)};
}

uint32_t groups(uint64_t items) {
  return vk::groupCount(std::max<uint64_t>(items, 1), bb::kWorkgroupSize);
}

void dispatchItems(const vk::ComputePipeline& p, VkCommandBuffer cmd, uint64_t items) {
  uint32_t g = groups(items);
  uint32_t rows = (g + bb::kMaxGroupsX - 1) / bb::kMaxGroupsX;
  p.dispatch(cmd, (g + rows - 1) / rows, rows);
}

BuildPush push(uint32_t triangleCount, uint32_t param) {
  BuildPush p{};
  p.triangleCount = triangleCount;
  p.param = param;
  return p;
}

BuildPush bindArrays(vk::Binder& binder, const ArrayAccess& access, const BuildArrayBuffers& a,
                     uint32_t triangleCount, uint32_t param) {
  const auto ranges = slots(a);
  const auto filler =
      std::find_if(ranges.begin(), ranges.end(), [](const vk::BufferRange& r) { return r.buffer; });
  if (filler == ranges.end()) throw DeviceError("bvh: a build pass got none of its arrays");
  const VkDeviceSize limit = access.ctx->caps().maxStorageBufferRange / 16 * 16;
  BuildPush p = push(triangleCount, param);
  glm::uvec2* addresses = &p.arrays.triangles;  // BuildArrays: one uvec2 per slot, in slot order
  static_assert(sizeof(bb::BuildArrays) >= bb::kBuildArrayBindingCount * sizeof(glm::uvec2));
  static_assert(offsetof(bb::BuildArrays, traversalNodes) ==
                bb::kBuildBindingTraversalNodes * sizeof(glm::uvec2));
  for (uint32_t i = 0; i < bb::kBuildArrayBindingCount; ++i) {
    vk::BufferRange r = ranges[i].buffer ? ranges[i] : *filler;
    if (access.byAddress) {
      if (ranges[i].buffer) {
        VkDeviceAddress at = r.buffer->deviceAddress() + r.offset;
        addresses[i] = {uint32_t(at), uint32_t(at >> 32)};
      }
      r.size = std::min(r.bytes(), limit);
    }
    binder.set(i, r);
  }
  return p;
}

std::vector<VkDescriptorType> storageAndTexelTypes(uint32_t bindingCount,
                                                   std::initializer_list<uint32_t> texelSlots) {
  std::vector<VkDescriptorType> t(bindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  for (uint32_t slot : texelSlots) t[slot] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}

std::vector<VkDescriptorType> texelTypes(uint32_t bindingCount, uint32_t texelBase) {
  std::vector<VkDescriptorType> t(bindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  for (uint32_t k = 0; k < bb::kBuildTexelBindingCount; ++k)
    t[texelBase + k] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}

std::vector<vk::SpecConstant> texelSpec(const vk::Context& ctx, bool byAddress,
                                        std::vector<vk::SpecConstant> spec) {
  const vk::Capabilities& caps = ctx.caps();
  uint64_t arrayBytes = byAddress
                            ? uint64_t(triangleLimit(ctx).triangles) * sizeof(bb::BvhBuildNode)
                            : uint64_t(caps.maxStorageBufferRange);
  spec.push_back(vk::specUint(bb::kBuildSpecTexels,
                              uint64_t(caps.maxTexelBufferElements) * 16 >= arrayBytes ? 1u : 0u));
  return spec;
}

bool wordTexelsCoverBindings(const vk::Context& ctx) {
  return uint64_t(ctx.caps().maxTexelBufferElements) * 4 >= ctx.caps().maxStorageBufferRange;
}

std::vector<VkDescriptorType> wordTexelTypes(uint32_t bindingCount, uint32_t texelBase,
                                             uint32_t wordTexels) {
  std::vector<VkDescriptorType> t = texelTypes(bindingCount, texelBase);
  t[wordTexels] = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return t;
}

std::vector<vk::SpecConstant> wordTexelSpec(const vk::Context& ctx, bool byAddress,
                                            uint32_t wordSpec) {
  std::vector<vk::SpecConstant> spec = texelSpec(ctx, byAddress, arraySpec(byAddress));
  spec.push_back(vk::specUint(wordSpec, wordTexelsCoverBindings(ctx) ? 1u : 0u));
  return spec;
}

void bindTexels(vk::Binder& binder, uint32_t texelBase, const BuildTexelViews& views) {
  binder.setTexel(texelBase + bb::kBuildTexelInterior, views.interior)
      .setTexel(texelBase + bb::kBuildTexelLeaves, views.leaves)
      .setTexel(texelBase + bb::kBuildTexelPrims, views.prims);
}

void recordClimb(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, vk::Binder& binder,
                 const ArrayAccess& access, const BuildArrayBuffers& arrays,
                 const BuildTexelViews& texels, uint32_t texelBase, const vk::BufferRange& counters,
                 uint32_t triangleCount) {
  vkCmdFillBuffer(cmd, counters.buffer->handle(), counters.offset, counters.bytes(), 0);
  vk::transferBarrier(cmd);
  BuildPush p = bindArrays(binder, access, arrays, triangleCount, 0);
  bindTexels(binder, texelBase, texels);
  binder.set(bb::kClimbBindingCounters, counters).bind(cmd, p);
  dispatchItems(pipeline, cmd, triangleCount);
  vk::computeBarrier(cmd);
}

void dispatchLevels(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                    const vk::Binder& binder, BuildPush push, const vk::Buffer& schedule,
                    uint32_t first, uint32_t levels) {
  const uint64_t argsOffset = levels * sizeof(bb::LevelList);
  for (uint32_t level = first; level < levels; ++level) {
    push.param = level;
    binder.bind(cmd, push);
    pipeline.dispatchIndirect(cmd, schedule, argsOffset + level * sizeof(bb::DispatchArgs));
    vk::computeBarrier(cmd);
  }
}

}  // namespace detail

bool BuildArrayBuffers::pastOneBinding(const vk::Context& ctx) const {
  for (const vk::BufferRange& r : slots(*this))
    if (r.buffer && r.bytes() > ctx.caps().maxStorageBufferRange) return true;
  return false;
}

}  // namespace osr::bvh
