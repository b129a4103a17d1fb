// unet: maps/s and achieved GFLOP/s of the U-Net engine for K x batch x precision, with the
// same network in PyTorch (/usr/bin/python3, torch.set_num_threads = cores) timed in the same
// run as the peer. Each configuration is checked against the CPU twin before it is timed.
// Lines: bench, K, batch, precision, maps_per_s, gflops, device, cpu_ms_per_map (process CPU
// time, all threads: comparable under load from other processes), ratio_vs_pytorch (maps/s)
// and cpu_ratio_vs_pytorch (PyTorch CPU ms per map / ours); peer lines add peer="pytorch".
// fp16 lines are compared with PyTorch fp32 (PyTorch has no fast fp16 CPU convolution).
// Usage: kUnetUsage in bench/benchmarks.h.
#include <chrono>
#include <ctime>
#include <cstdio>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "app/args.h"
#include "bench/benchmarks.h"
#include "bench/json.h"
#include "common/error.h"
#include "nn_kernels/unet.h"
#include "nn_kernels/unet_cpu.h"
#include "vk/buffer.h"
#include "vk/timer.h"

namespace osr::bench {

namespace {

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

struct PeerResult {
  double mapsPerS = -1;  // negative: the peer could not run
  double cpuMsPerMap = -1;
};

// PyTorch's throughput for (K, batch).
PeerResult pytorchPeer(uint32_t k, uint32_t batch, unsigned threads, double minSeconds) {
  const std::string cmd = "/usr/bin/python3 " + std::string(OSR_SOURCE_DIR) +
                          "/tools/bench_unet_torch.py --k " + std::to_string(k) + " --batch " +
                          std::to_string(batch) + " --threads " + std::to_string(threads) +
                          " --min-seconds " + std::to_string(minSeconds) + " 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  if (!pipe) return {};
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, pipe.get())) out += buf;
  try {
    auto j = nlohmann::json::parse(out);
    return {j.at("maps_per_s").get<double>(), j.at("cpu_ms_per_map").get<double>()};
  } catch (const std::exception&) {
    return {};
  }
}

}  // namespace

int runUnet(const std::vector<std::string>& args) {
  app::Args a(args, "unet");
  std::vector<uint32_t> ks = {16, 64}, batches = {64, 256, 1024, 4096};
  if (auto v = a.integerList("--k", 1, 1024)) ks.assign(v->begin(), v->end());
  if (auto v = a.integerList("--batch", 1, 1 << 20)) batches.assign(v->begin(), v->end());
  std::vector<std::string> precisions = {"fp32", "fp16"};
  if (auto v = a.value("--precision")) precisions = splitList(*v);
  for (auto& p : precisions)
    if (p != "fp32" && p != "fp16") throw InputError("unet: --precision takes fp32,fp16");
  const bool profile = a.flag("--profile");  // per-pass GPU times of one batch on stderr
  const bool pytorch = !a.flag("--no-pytorch");
  const double minSeconds = a.number("--min-seconds", 0, 3600).value_or(2.0);
  nn::UNetOptions base;
  base.maxChunk = uint32_t(a.integer("--chunk", 1, 1 << 20).value_or(base.maxChunk));
  // 1: no load sharing, 9: sharing over 8 lanes; absent: the device's choice (-1).
  base.shareLoads = int(a.integer("--share", 1, 65).value_or(0)) - 1;
  if (auto tile = a.integerList("--tile", 1, 32, 'x')) {
    if (tile->size() != 2) throw InputError("unet: option --tile takes HxW, e.g. 4x8");
    base.tileH = uint32_t((*tile)[0]);
    base.tileW = uint32_t((*tile)[1]);
  }
  a.finish();

  vk::Context ctx;
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  constexpr size_t kInMap = 7 * 32 * 32, kOutMap = 3 * 32 * 32;
  int rc = 0;
  for (uint32_t k : ks) {
    std::map<uint32_t, PeerResult> peer;  // batch -> PyTorch fp32, measured once per K
    for (const std::string& precision : precisions) {
      const bool half = precision == "fp16";
      nn::UNetWeights w = nn::UNetWeights::random(k, 7, half);
      nn::UNetOptions opt = base;
      opt.half = half;
      nn::UNet net(ctx, w, opt);
      for (uint32_t batch : batches) {
        std::vector<float> maps(batch * kInMap);
        std::mt19937 rng(batch);
        std::uniform_real_distribution<float> uni(-0.5f, 1.5f);
        for (float& v : maps) v = uni(rng);
        vk::Buffer in(ctx, maps.size() * 4, vk::MemoryUse::DeviceLocal, "bench unet in");
        in.uploadVector(maps);
        vk::Buffer out(ctx, batch * kOutMap * 4, vk::MemoryUse::DeviceLocal, "bench unet out");
        auto record = [&](VkCommandBuffer cmd) { net.record(cmd, in, 0, out, 0, batch); };

        // Verify the first and last map against the CPU twin before timing.
        auto t0 = std::chrono::steady_clock::now();
        ctx.submitAndWait(record);
        const double firstSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        for (uint32_t m : {0u, batch - 1}) {
          nn::Tensor one(1, 7, 32, 32);
          std::copy_n(maps.begin() + m * kInMap, kInMap, one.data.begin());
          nn::Tensor ref = nn::unetCpu(w, one);
          std::vector<float> got = out.downloadVector<float>(kOutMap, m * kOutMap * 4);
          double diff = 0, scale = 1e-30;
          for (size_t i = 0; i < kOutMap; ++i) {
            diff = std::max(diff, double(std::fabs(got[i] - ref.data[i])));
            scale = std::max(scale, double(std::fabs(ref.data[i])));
          }
          if (!(diff / scale <= (half ? 1e-2 : 1e-4))) {
            std::fprintf(stderr, "unet: K=%u batch=%u %s: map %u differs from the CPU twin (rel %.3g)\n",
                         k, batch, precision.c_str(), m, diff / scale);
            rc = 1;
          }
        }

        // Time whole submissions (the engine is one command buffer per batch).
        int reps = 0;
        double seconds = 0;
        // Process CPU time too: on a shared CPU (lavapipe) it compares variants under load.
        timespec cpu0{}, cpu1{};
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu0);
        const int minReps = firstSeconds > minSeconds ? 1 : 2;
        while (reps < minReps || seconds < minSeconds) {
          auto s = std::chrono::steady_clock::now();
          ctx.submitAndWait(record);
          seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s).count();
          ++reps;
        }
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu1);
        const double cpuSeconds = double(cpu1.tv_sec - cpu0.tv_sec) + 1e-9 * double(cpu1.tv_nsec - cpu0.tv_nsec);
        const double mapsPerS = batch * reps / seconds;
        if (profile && ctx.caps().timestamps) {
          vk::GpuTimer timer(ctx, 64 * (batch / net.chunkMaps() + 1));
          ctx.submitAndWait([&](VkCommandBuffer cmd) {
            timer.reset(cmd);
            net.record(cmd, in, 0, out, 0, batch, &timer);
          });
          std::map<std::string, double> perPass;
          for (const vk::PassTime& t : timer.results()) perPass[t.name] += t.ms;
          for (auto& [name, ms] : perPass) std::fprintf(stderr, "  %-12s %8.2f ms\n", name.c_str(), ms);
        }
        const double gflops = mapsPerS * net.flopsPerMap() / 1e9;
        if (pytorch && !peer.count(batch)) {
          const PeerResult pr = pytorchPeer(k, batch, threads, minSeconds);
          const double p = pr.mapsPerS;
          peer[batch] = pr;
          if (p > 0)
            JsonLine()
                .str("bench", "unet")
                .integer("K", k)
                .integer("batch", batch)
                .str("precision", "fp32")
                .num("maps_per_s", p)
                .num("gflops", p * net.flopsPerMap() / 1e9)
                .str("device", "cpu")
                .integer("threads", threads)
                .str("peer", "pytorch")
                .num("cpu_ms_per_map", pr.cpuMsPerMap)
                .print();
          else
            std::fprintf(stderr, "unet: PyTorch peer unavailable (/usr/bin/python3 with torch)\n");
        }
        JsonLine line;
        line.str("bench", "unet")
            .integer("K", k)
            .integer("batch", batch)
            .str("precision", precision)
            .num("maps_per_s", mapsPerS)
            .num("gflops", gflops)
            .str("device", ctx.caps().deviceName)
            .integer("chunk", net.chunkMaps())
            .integer("reps", reps)
            .num("cpu_ms_per_map", 1e3 * cpuSeconds / (double(batch) * reps));
        if (peer.count(batch) && peer[batch].mapsPerS > 0)
          line.num("ratio_vs_pytorch", mapsPerS / peer[batch].mapsPerS)
              .num("cpu_ratio_vs_pytorch", peer[batch].cpuMsPerMap / (1e3 * cpuSeconds / (double(batch) * reps)));
        line.print();
      }
    }
  }
  return rc;
}

}  // namespace osr::bench
