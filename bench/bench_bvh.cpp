// bvh: GPU build time per pass and in total, Mtriangles/s, SAH of the GPU tree and of the CPU
// binned-SAH tree, and Embree (2 threads, same cores, same run) as the peer. Every GPU tree is
// checked for the structural invariants before it is timed.
#include <chrono>
#include <cstdio>
#include <limits>

#include "app/args.h"
#include "bench/benchmarks.h"
#include "bench/bvh_scenes.h"
#include "bench/embree_peer.h"
#include "bench/json.h"
#include "bvh/cpu_builder.h"
#include "bvh/gpu_builder.h"
#include "bvh/tree_stats.h"
#include "vk/buffer.h"

namespace osr::bench {

namespace {
double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

int runBvh(const std::vector<std::string>& argv) {
  app::Args args(argv, "bvh");
  std::string only = args.value("--scene").value_or("");
  uint32_t triangles = uint32_t(args.integer("--triangles", 1, 1ll << 27).value_or(0));
  bool cpuReference = !args.flag("--no-cpu-reference");
  int repeat = int(args.integer("--repeat", 1, 100).value_or(3));
  bvh::GpuBuildOptions options;
  // Unset: bvh::treeletRoundsFor's choice per scene (what the renderer builds).
  if (auto rounds = args.integer("--treelet-rounds", 0, 8)) options.treeletRounds = uint32_t(*rounds);
  options.treeletLeaves = uint32_t(
      args.integer("--treelet-leaves", 3, gpu::bvh_build::kTreeletMaxLeaves).value_or(options.treeletLeaves));
  options.treeletMinTriangles =
      uint32_t(args.integer("--treelet-min-triangles", 3, 1 << 20).value_or(options.treeletMinTriangles));
  hierarchyOptions(args, "bvh", options);
  args.finish();
  vk::Context ctx;
  bvh::GpuBuilder builder(ctx, options);
  for (const BvhBenchScene& s : bvhBenchScenes(only, triangles)) {
    const auto& m = s.mesh;
    const uint32_t n = uint32_t(m.triangles.size());
    // With texel usage, as gpu::GpuScene makes them (bvh_bounds then reads them through views).
    vk::Buffer vertices(ctx, m.vertices.size() * sizeof(gpu::scene::Vertex), vk::MemoryUse::DeviceLocal, "bench vertices",
                        VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
    vk::Buffer triangles(ctx, m.triangles.size() * sizeof(gpu::scene::Triangle), vk::MemoryUse::DeviceLocal,
                         "bench triangles", VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
    vertices.uploadVector(m.vertices);
    triangles.uploadVector(m.triangles);

    // The builder's first build at this size allocates the scratch buffers the timed builds reuse
    // (first_build_ms), then the best of `repeat` builds (GPU timestamps; wall time alongside).
    // All of these write only the node form traversal reads, as the renderer's build does; a last
    // build writes both (bvh::NodeForms::Both) for the checks and the SAH, which read the exact
    // nodes.
    bvh::BuildStats stats;
    uint64_t bvhBytes = 0;
    const auto firstStart = std::chrono::steady_clock::now();
    {
      bvh::Bvh tree = builder.build(vertices, triangles, n, &stats);
      bvhBytes = tree.nodes.size() + tree.traversalNodes.size() + tree.leafData.size();
    }
    const double firstBuildMs = stats.totalMs, firstBuildWallMs = msSince(firstStart);
    bvh::BuildStats best;
    best.totalMs = std::numeric_limits<double>::infinity();
    double bestWall = best.totalMs, bestCpu = best.totalMs;
    for (int r = 0; r < repeat; ++r) {
      auto start = std::chrono::steady_clock::now();
      double cpuStart = processCpuMs();
      builder.build(vertices, triangles, n, &stats);
      bestCpu = std::min(bestCpu, processCpuMs() - cpuStart);
      bestWall = std::min(bestWall, msSince(start));
      if (stats.totalMs < best.totalMs) best = stats;
    }
    bvh::HostBvh gpuTree = bvh::download(builder.build(vertices, triangles, n, nullptr, bvh::NodeForms::Both));
    std::string problem = bvh::checkInvariants(gpuTree, m.vertices, m.triangles);
    if (!problem.empty()) {
      std::fprintf(stderr, "osr-bench bvh: %s: GPU tree invalid: %s\n", s.name.c_str(), problem.c_str());
      return 1;
    }
    double sahGpu = bvh::sahCost(gpuTree);
    double cpuMs = 0, sahCpu = 0;
    if (cpuReference) {
      auto cpuStart = std::chrono::steady_clock::now();
      bvh::HostBvh cpuTree = bvh::buildCpu(m.vertices, m.triangles);
      cpuMs = msSince(cpuStart);
      sahCpu = bvh::sahCost(cpuTree);
    }

    JsonLine line;
    line.str("bench", "bvh").str("scene", s.name).integer("triangles", n).str("device", ctx.caps().deviceName);
    line.num("build_ms", best.totalMs).num("mtris_per_s", n / (best.totalMs * 1e3)).num("first_build_ms", firstBuildMs).num("first_build_wall_ms", firstBuildWallMs);
    line.num("sah_gpu", sahGpu);
    if (cpuReference) line.num("sah_cpu", sahCpu).num("sah_ratio", sahGpu / sahCpu);
    line.integer("treelet_rounds", best.treeletRounds).integer("treelet_leaves", options.treeletLeaves);
    line.integer("treelet_min_triangles", options.treeletMinTriangles).integer("ploc_iterations", best.plocIterations);
    line.integer("ploc_local_rounds", best.plocLocalRounds).integer("ploc_tail_clusters", best.plocTailClusters);
    line.integer("depth", bvh::depth(gpuTree)).num("wall_ms", bestWall).num("cpu_time_ms", bestCpu);
    if (cpuReference) line.num("cpu_build_ms", cpuMs);
    // Memory per triangle. Device: the scene's vertex and triangle buffers, the BVH the renderer
    // keeps, and the build's scratch (freed after the build). Host: the mesh arrays; the peak
    // resident size covers the whole process (on lavapipe, device memory too).
    const double perTri = 1.0 / n;
    line.num("device_scene_bytes_per_triangle", double(vertices.size() + triangles.size()) * perTri)
        .num("device_bvh_bytes_per_triangle", double(bvhBytes) * perTri)
        .num("device_build_scratch_bytes_per_triangle", double(stats.scratchBytes) * perTri)
        .num("host_scene_bytes_per_triangle",
             double(m.vertices.size() * sizeof(gpu::scene::Vertex) + m.triangles.size() * sizeof(gpu::scene::Triangle)) * perTri)
        .num("peak_rss_mib", double(peakRssBytes()) / (1 << 20));
    for (const auto& p : best.passes) line.num(("pass_" + p.name + "_ms").c_str(), p.ms);
#ifdef OSR_HAVE_EMBREE
    EmbreePeer peer(m, 2);
    double embreeMs = std::numeric_limits<double>::infinity(), embreeCpu = embreeMs;
    EmbreePeer::BinaryBvh binary;
    binary.ms = embreeMs;
    for (int r = 0; r < repeat; ++r) {
      double cpuStart = processCpuMs();
      embreeMs = std::min(embreeMs, peer.buildScene());
      embreeCpu = std::min(embreeCpu, processCpuMs() - cpuStart);
      auto b = peer.buildBinaryBvh();
      if (b.ms < binary.ms) binary = b;
    }
    // Wall time against Embree's (rtcCommitScene, its allocations included): ours includes what
    // the build does on the host around its GPU passes (allocating and populating the BVH's
    // arrays), which build_ms, from GPU timestamps, leaves out.
    line.num("build_ratio_vs_embree", bestWall / embreeMs).num("cpu_time_ratio_vs_embree", bestCpu / embreeCpu);
    line.print();
    JsonLine peerLine;
    peerLine.str("bench", "bvh")
        .str("peer", "embree")
        .str("scene", s.name)
        .integer("triangles", n)
        .str("device", "Embree 3 on the CPU, 2 threads")
        .num("build_ms", embreeMs)
        .num("mtris_per_s", n / (embreeMs * 1e3))
        .num("cpu_time_ms", embreeCpu)
        .num("sah_embree", binary.sah);
    if (cpuReference) peerLine.num("sah_cpu", sahCpu);
    peerLine.num("bvh_build_ms", binary.ms).integer("depth", binary.depth).print();
#else
    line.print();
#endif
  }
  return 0;
}

}  // namespace osr::bench
