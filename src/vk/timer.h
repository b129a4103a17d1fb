// GPU timestamps around named passes. Each pass records begin(cmd, name) ... end(cmd); the
// scope also carries a debug label so captures show the same names. Read results after the
// command buffer has completed.
#pragma once
#include <vulkan/vulkan.h>

#include <string>
#include <vector>

#include "vk/context.h"

namespace osr::vk {

struct PassTime {
  std::string name;
  double ms = 0.0;
};

class GpuTimer {
 public:
  // Room for `maxScopes` begin/end pairs per recording.
  GpuTimer(const Context& ctx, uint32_t maxScopes = 128);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  // Resets the query pool; record before the first begin() of a command buffer.
  void reset(VkCommandBuffer cmd);
  void begin(VkCommandBuffer cmd, const std::string& name);
  void end(VkCommandBuffer cmd);
  // Per-scope durations of the last completed recording, in recording order.
  std::vector<PassTime> results() const;
  // Sum of results() with the same name (a pass recorded several times).
  double totalMs(const std::string& name) const;

 private:
  const Context& ctx_;
  uint32_t maxScopes_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  std::vector<std::string> names_;
  int open_ = -1;
};

// RAII helper: GpuTimer::begin on construction, end on destruction. timer may be null.
class TimedScope {
 public:
  TimedScope(GpuTimer* timer, VkCommandBuffer cmd, const std::string& name)
      : timer_(timer), cmd_(cmd) {
    if (timer_) timer_->begin(cmd_, name);
  }
  ~TimedScope() {
    if (timer_) timer_->end(cmd_);
  }
  TimedScope(const TimedScope&) = delete;
  TimedScope& operator=(const TimedScope&) = delete;

 private:
  GpuTimer* timer_;
  VkCommandBuffer cmd_;
};

}  // namespace osr::vk
