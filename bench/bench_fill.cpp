// fill: bandwidth of the simplest pass, a sanity figure for the device and the timer.
#include "app/args.h"
#include "bench/benchmarks.h"
#include "bench/json.h"
#include "shaders/shared/util_fill.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"
#include "vk/timer.h"

namespace osr::bench {

int runFill(const std::vector<std::string>& args) {
  app::Args(args, "fill").finish();  // no options: refuse any rather than ignore them
  vk::Context ctx;
  namespace fill = gpu::util_fill;
  // 64 Ki groups of 64 is the most one 1-D dispatch may have on every device.
  const uint32_t words = 65535u * fill::kWorkgroupSize;
  vk::Buffer buf(ctx, words * 4ull, vk::MemoryUse::DeviceLocal, "fill bench");
  vk::ComputePipeline pass(ctx, shaders::Id::util_fill, 1, sizeof(fill::Push));
  vk::GpuTimer timer(ctx);
  for (int rep = 0; rep < 3; ++rep)
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
      timer.reset(cmd);
      vk::TimedScope scope(&timer, cmd, "util_fill");
      vk::Binder(pass).set(fill::kBindingData, buf).bind(cmd, fill::Push{words, 1u});
      pass.dispatch(cmd, vk::groupCount(words, fill::kWorkgroupSize));
    });
  if (buf.downloadVector<uint32_t>(1, (words - 1) * 4ull)[0] != 1u) return 1;
  double ms = timer.totalMs("util_fill");
  JsonLine()
      .str("bench", "fill")
      .str("device", ctx.caps().deviceName)
      .integer("bytes", words * 4ll)
      .num("ms", ms)
      .num("gb_per_s", words * 4.0 / (ms * 1e6))
      .print();
  return 0;
}

}  // namespace osr::bench
