#include "vk/pipeline.h"

#include "common/error.h"
#include "vk/check.h"
#include "vk/spirv_info.h"

namespace osr::vk {
namespace {
// A pass that uses subgroup operations assumes whole subgroups of consecutive invocations
// (docs/subgroups.md). Its workgroup must hold whole subgroups, and where the device may split
// them the pipeline asks for full ones.
VkPipelineShaderStageCreateFlags subgroupFlags(const Context& ctx, const shaders::Module& m,
                                               const std::vector<SpecConstant>& spec) {
  const SpirvComputeInfo info = readSpirvComputeInfo({m.code, m.words}, spec);
  if (!info.usesSubgroups) return 0;
  const uint32_t size = ctx.caps().subgroupSize;
  if (info.localSize[0] % size != 0)
    throw DeviceError(std::string(m.name) + ": workgroup of " + std::to_string(info.localSize[0]) +
                      " invocations does not hold whole subgroups of " + std::to_string(size));
  return ctx.caps().requireFullSubgroups ? VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT_EXT
                                         : 0;
}
}  // namespace

ComputePipeline::ComputePipeline(const Context& ctx, shaders::Id shader, uint32_t bindingCount,
                                 uint32_t pushBytes, const std::vector<SpecConstant>& spec)
    : ComputePipeline(ctx, shader,
                      std::vector<VkDescriptorType>(bindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER),
                      pushBytes, spec) {}

ComputePipeline::ComputePipeline(const Context& ctx, shaders::Id shader,
                                 std::vector<VkDescriptorType> types, uint32_t pushBytes,
                                 const std::vector<SpecConstant>& spec)
    : ComputePipeline() {
  // Delegating to the default constructor completes the object before this body runs, so a
  // throw below runs ~ComputePipeline and frees the module and layouts made so far.
  ctx_ = &ctx;
  bindingCount_ = uint32_t(types.size());
  pushBytes_ = pushBytes;
  types_ = std::move(types);
  const uint32_t bindingCount = bindingCount_;
  const shaders::Module& m = shaders::module(shader);
  name_ = m.name;
  VkDevice dev = ctx.device();

  VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  moduleInfo.codeSize = m.words * 4;
  moduleInfo.pCode = m.code;
  check(vkCreateShaderModule(dev, &moduleInfo, nullptr, &module_), name_);
  ctx.setName(VK_OBJECT_TYPE_SHADER_MODULE, reinterpret_cast<uint64_t>(module_), name_);

  std::vector<VkDescriptorSetLayoutBinding> bindings(bindingCount);
  for (uint32_t i = 0; i < bindingCount; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = types_[i];
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  setInfo.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
  setInfo.bindingCount = bindingCount;
  setInfo.pBindings = bindings.data();
  check(vkCreateDescriptorSetLayout(dev, &setInfo, nullptr, &setLayout_), name_);

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
  VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &setLayout_;
  layoutInfo.pushConstantRangeCount = pushBytes ? 1 : 0;
  layoutInfo.pPushConstantRanges = &range;
  check(vkCreatePipelineLayout(dev, &layoutInfo, nullptr, &layout_), name_);

  std::vector<VkSpecializationMapEntry> entries;
  std::vector<uint32_t> values;
  for (size_t i = 0; i < spec.size(); ++i) {
    entries.push_back({spec[i].id, static_cast<uint32_t>(i * 4), 4});
    values.push_back(spec[i].bits);
  }
  VkSpecializationInfo specInfo{static_cast<uint32_t>(entries.size()), entries.data(),
                                values.size() * 4, values.data()};
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module_;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = spec.empty() ? nullptr : &specInfo;
  info.stage.flags = subgroupFlags(ctx, m, spec);
  info.layout = layout_;
  check(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_), name_);
  ctx.setName(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<uint64_t>(pipeline_), name_);
}

ComputePipeline::~ComputePipeline() { release(); }

ComputePipeline::ComputePipeline(ComputePipeline&& o) noexcept { *this = std::move(o); }

ComputePipeline& ComputePipeline::operator=(ComputePipeline&& o) noexcept {
  if (this != &o) {
    release();
    ctx_ = o.ctx_;
    name_ = o.name_;
    bindingCount_ = o.bindingCount_;
    pushBytes_ = o.pushBytes_;
    types_ = std::move(o.types_);
    module_ = o.module_;
    setLayout_ = o.setLayout_;
    layout_ = o.layout_;
    pipeline_ = o.pipeline_;
    o.module_ = VK_NULL_HANDLE;
    o.setLayout_ = VK_NULL_HANDLE;
    o.layout_ = VK_NULL_HANDLE;
    o.pipeline_ = VK_NULL_HANDLE;
  }
  return *this;
}

void ComputePipeline::release() {
  if (!ctx_) return;
  VkDevice dev = ctx_->device();
  if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
  if (setLayout_) vkDestroyDescriptorSetLayout(dev, setLayout_, nullptr);
  if (module_) vkDestroyShaderModule(dev, module_, nullptr);
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
  module_ = VK_NULL_HANDLE;
}

void ComputePipeline::checkPushSize(size_t bytes) const {
  if (bytes != pushBytes_)
    throw DeviceError(std::string(name_) + ": push constants of " + std::to_string(bytes) +
                      " bytes, pipeline declares " + std::to_string(pushBytes_));
}

void ComputePipeline::bindWrites(VkCommandBuffer cmd, std::span<const VkWriteDescriptorSet> writes,
                                 const void* push, size_t pushBytes) const {
  checkPushSize(pushBytes);
  if (writes.size() != bindingCount_)
    throw DeviceError(std::string(name_) + ": " + std::to_string(writes.size()) +
                      " descriptors bound, pipeline declares " + std::to_string(bindingCount_));
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  if (!writes.empty())
    ctx_->cmdPushDescriptorSet(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0,
                               static_cast<uint32_t>(writes.size()), writes.data());
  if (pushBytes_) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes_, push);
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, uint32_t x, uint32_t y, uint32_t z) const {
  const uint32_t* maxCount = ctx_->caps().maxComputeWorkGroupCount;
  if (x > maxCount[0] || y > maxCount[1] || z > maxCount[2])
    throw DeviceError(std::string(name_) + ": dispatch of " + std::to_string(x) + "x" +
                      std::to_string(y) + "x" + std::to_string(z) +
                      " groups exceeds maxComputeWorkGroupCount");
  if (x && y && z) vkCmdDispatch(cmd, x, y, z);
}

void ComputePipeline::dispatchIndirect(VkCommandBuffer cmd, const Buffer& args,
                                       VkDeviceSize offset) const {
  vkCmdDispatchIndirect(cmd, args.handle(), offset);
}


}  // namespace osr::vk
