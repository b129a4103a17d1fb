#include "vk/timer.h"

#include "common/error.h"
#include "vk/check.h"

namespace osr::vk {

GpuTimer::GpuTimer(const Context& ctx, uint32_t maxScopes) : ctx_(ctx), maxScopes_(maxScopes) {
  if (!ctx.caps().timestamps) return;
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = maxScopes * 2;
  check(vkCreateQueryPool(ctx.device(), &info, nullptr, &pool_), "vkCreateQueryPool");
}

GpuTimer::~GpuTimer() {
  if (pool_) vkDestroyQueryPool(ctx_.device(), pool_, nullptr);
}

void GpuTimer::reset(VkCommandBuffer cmd) {
  names_.clear();
  open_ = -1;
  if (pool_) vkCmdResetQueryPool(cmd, pool_, 0, maxScopes_ * 2);
}

void GpuTimer::begin(VkCommandBuffer cmd, const std::string& name) {
  if (open_ >= 0) throw DeviceError("GpuTimer: scope '" + name + "' opened inside another");
  if (names_.size() >= maxScopes_) throw DeviceError("GpuTimer: more than maxScopes scopes");
  ctx_.beginLabel(cmd, name.c_str());
  open_ = static_cast<int>(names_.size());
  names_.push_back(name);
  if (pool_)
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_, 2 * open_);
}

void GpuTimer::end(VkCommandBuffer cmd) {
  if (open_ < 0) throw DeviceError("GpuTimer: end() without begin()");
  if (pool_)
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, 2 * open_ + 1);
  ctx_.endLabel(cmd);
  open_ = -1;
}

std::vector<PassTime> GpuTimer::results() const {
  std::vector<PassTime> out;
  if (names_.empty()) return out;
  std::vector<uint64_t> stamps(names_.size() * 2, 0);
  if (pool_)
    check(vkGetQueryPoolResults(ctx_.device(), pool_, 0, static_cast<uint32_t>(stamps.size()),
                                stamps.size() * sizeof(uint64_t), stamps.data(),
                                sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
  for (size_t i = 0; i < names_.size(); ++i) {
    double ns = static_cast<double>(stamps[2 * i + 1] - stamps[2 * i]) * ctx_.caps().timestampPeriodNs;
    out.push_back({names_[i], ns * 1e-6});
  }
  return out;
}

double GpuTimer::totalMs(const std::string& name) const {
  double sum = 0.0;
  for (const PassTime& t : results())
    if (t.name == name) sum += t.ms;
  return sum;
}

}  // namespace osr::vk
