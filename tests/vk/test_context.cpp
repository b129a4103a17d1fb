// The Vulkan core: a pass dispatched through ComputePipeline writes what its CPU twin expects,
// buffers round-trip through staging, oversize bindings are refused, timestamps are recorded.
#include <gtest/gtest.h>
#include <sched.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "common/error.h"
#include "shaders/shared/util_fill.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/debug_labels.h"
#include "vk/pipeline.h"
#include "vk/timer.h"
#include "common/vk_test.h"

using namespace osr;
namespace fill = osr::gpu::util_fill;

TEST(Context, ChoosesADeviceWithCompute) {
  auto& ctx = test::context();
  EXPECT_TRUE(ctx.validationEnabled());
  EXPECT_GE(ctx.caps().subgroupSize, 1u);
  // CI sets the size it asked lavapipe for (LP_NATIVE_VECTOR_WIDTH 256: 8 lanes, 128: 4), so
  // that a run meant for one size cannot pass at the other.
  if (const char* want = std::getenv("OSR_TEST_EXPECT_SUBGROUP_SIZE")) {
    EXPECT_EQ(ctx.caps().subgroupSize, uint32_t(std::stoul(want))) << ctx.caps().deviceName;
  }
  EXPECT_GE(ctx.caps().maxStorageBufferRange, 1u << 27);
  EXPECT_FALSE(vk::listDevices().empty());
}

TEST(Context, CommandLabelsOnlyUnderALayerThatLocksThem) {
  EXPECT_TRUE(vk::commandLabelsSafe(0));  // no validation layer
  EXPECT_FALSE(vk::commandLabelsSafe(VK_MAKE_API_VERSION(0, 1, 3, 239)));  // Debian 12's
  EXPECT_FALSE(vk::commandLabelsSafe(VK_MAKE_API_VERSION(0, 1, 3, 242)));
  EXPECT_TRUE(vk::commandLabelsSafe(VK_MAKE_API_VERSION(0, 1, 3, 243)));
  EXPECT_TRUE(vk::commandLabelsSafe(VK_MAKE_API_VERSION(0, 1, 4, 300)));
}

// The pattern that corrupted the heap inside validation layer 1.3.239 (docs/testing.md): many
// one-shot submissions with a label each, on one CPU so that the layer's queue thread is
// preempted between signalling the fence and dropping its last reference to the freed command
// buffer. With labels recorded under that layer this test fails (std::bad_alloc or abort)
// within seconds; tools/repro/vvl_label_race.cpp does the same without osr-vk.
TEST(Context, ManyLabelledOneShotSubmissionsOnOneCpu) {
  struct Pinned {  // the process on its first allowed CPU, restored whatever happens
    cpu_set_t saved;
    Pinned() {
      if (sched_getaffinity(0, sizeof(saved), &saved) != 0) throw std::runtime_error("affinity");
      cpu_set_t one;
      CPU_ZERO(&one);
      for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
        if (CPU_ISSET(cpu, &saved)) {
          CPU_SET(cpu, &one);
          break;
        }
      if (sched_setaffinity(0, sizeof(one), &one) != 0) throw std::runtime_error("affinity");
    }
    ~Pinned() { sched_setaffinity(0, sizeof(saved), &saved); }
  } pinned;
  // Its own context, so that the layer's queue thread starts on the one CPU too.
  vk::ContextOptions options;
  options.validation = true;
  vk::Context ctx(options);
  // 100 000 rounds take about 5 s on an idle core; on a busy one each hand-over between the
  // threads waits for the scheduler, so the loop also stops after 20 s.
  const auto stop = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  for (int i = 0; i < 100000 && std::chrono::steady_clock::now() < stop; ++i)
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
      ctx.beginLabel(cmd, "one-shot");
      ctx.endLabel(cmd);
    });
  EXPECT_EQ(ctx.validationMessages(), 0u);
}

TEST(Context, FillPassWritesExactlyCountWords) {
  auto& ctx = test::context();
  // Odd sizes hit the tail of the last workgroup.
  for (uint32_t count : {1u, 63u, 64u, 65u, 1000u}) {
    vk::Buffer buf(ctx, (count + 7) * 4, vk::MemoryUse::DeviceLocal, "fill target");
    std::vector<uint32_t> init(count + 7, 0xdeadbeefu);
    buf.uploadVector(init);
    vk::ComputePipeline pass(ctx, shaders::Id::util_fill, 1, sizeof(fill::Push));
    vk::GpuTimer timer(ctx);
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
      timer.reset(cmd);
      vk::TimedScope scope(&timer, cmd, "util_fill");
      vk::Binder(pass).set(fill::kBindingData, buf).bind(cmd, fill::Push{count, 42u});
      pass.dispatch(cmd, vk::groupCount(count, fill::kWorkgroupSize));
    });
    auto out = buf.downloadVector<uint32_t>(count + 7);
    for (uint32_t i = 0; i < count + 7; ++i)
      ASSERT_EQ(out[i], i < count ? 42u : 0xdeadbeefu) << "count " << count << " word " << i;
    auto times = timer.results();
    ASSERT_EQ(times.size(), 1u);
    EXPECT_GE(times[0].ms, 0.0);
  }
}

TEST(Context, StagingRoundTripAtOffsets) {
  auto& ctx = test::context();
  for (auto use : {vk::MemoryUse::DeviceLocal, vk::MemoryUse::HostUpload, vk::MemoryUse::HostReadback}) {
    vk::Buffer buf(ctx, 4096, use, "round trip");
    std::vector<float> data(100);
    for (size_t i = 0; i < data.size(); ++i) data[i] = float(i) * 0.5f;
    buf.uploadVector(data, 256);
    auto back = buf.downloadVector<float>(100, 256);
    EXPECT_EQ(back, data);
    EXPECT_THROW(buf.upload(data.data(), 4096, 4), DeviceError);
  }
}

TEST(Context, BindingPastMaxStorageBufferRangeIsRefused) {
  auto& ctx = test::context();
  VkDeviceSize limit = ctx.caps().maxStorageBufferRange;
  // GPUs whose storage range (4 GiB on NVIDIA's drivers) reaches their largest allocation
  // cannot hold a buffer past it: the allocation is refused first (app/test_cli_errors).
  if (limit + 1024 > ctx.caps().maxMemoryAllocationSize)
    GTEST_SKIP() << "maxStorageBufferRange " << limit << " is not below maxMemoryAllocationSize "
                 << ctx.caps().maxMemoryAllocationSize;
  vk::Buffer big(ctx, limit + 1024, vk::MemoryUse::DeviceLocal, "too big");
  vk::ComputePipeline pass(ctx, shaders::Id::util_fill, 1, sizeof(fill::Push));
  try {
    ctx.submitAndWait([&](VkCommandBuffer cmd) { vk::Binder(pass).set(fill::kBindingData, big).bind(cmd, fill::Push{1, 0}); });
    FAIL() << "expected a DeviceError";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("maxStorageBufferRange"), std::string::npos) << e.what();
  }
  // A chunk inside the limit binds and runs.
  ctx.submitAndWait([&](VkCommandBuffer cmd) {
    vk::Binder(pass).setRange(fill::kBindingData, big, 1024, limit).bind(cmd, fill::Push{16, 7});
    pass.dispatch(cmd, 1);
  });
  auto out = big.downloadVector<uint32_t>(4, 1024);
  EXPECT_EQ(out[0], 7u);
}
