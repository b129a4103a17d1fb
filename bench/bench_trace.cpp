// trace: Mrays/s of bvh_trace_rays (closest hit) on the GPU-built tree, for primary rays (a
// pinhole camera's pixel grid: coherent) and diffuse-bounce rays (cosine directions from
// random surface points: incoherent), with Embree's rtcIntersect1 on 2 threads as the peer.
// The GPU hits are first checked against the CPU twin of the traversal on the same tree.
// --bvh-access storage|texel forces how traversal reads the BVH (for comparing the two).
// --rays-per-lane lists the ray-pool sizes to time (see bvh::TraceRaysPass::Args::raysPerLane).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>

#include "app/args.h"
#include "common/error.h"
#include "bench/benchmarks.h"
#include "bench/bvh_scenes.h"
#include "bench/embree_peer.h"
#include "bench/json.h"
#include "bvh/gpu_builder.h"
#include "bvh/host_trace.h"
#include "bvh/trace_rays.h"
#include "bvh/tree_stats.h"
#include "vk/timer.h"

namespace osr::bench {

namespace {

using gpu::bvh_trace::TraceHit;
using gpu::bvh_trace::TraceRay;

std::vector<TraceRay> primaryRays(const BvhBenchScene& s, uint32_t side) {
  std::vector<TraceRay> rays(size_t(side) * side);
  glm::vec3 origin(s.worldFromCamera[3]);
  glm::mat3 rot(s.worldFromCamera);
  float tanHalf = std::tan(0.5f * s.yfov);
  for (uint32_t y = 0; y < side; ++y)
    for (uint32_t x = 0; x < side; ++x) {
      glm::vec3 d((2.0f * (x + 0.5f) / side - 1.0f) * tanHalf, (1.0f - 2.0f * (y + 0.5f) / side) * tanHalf, -1.0f);
      rays[size_t(y) * side + x] = {origin, 0.0f, glm::normalize(rot * d), std::numeric_limits<float>::infinity()};
    }
  return rays;
}

// Area-weighted random points on random triangles, leaving on a random side along a cosine
// distribution about the geometric normal; origins nudged off the surface by 1e-5 of the scene.
std::vector<TraceRay> diffuseRays(const BvhBenchScene& s, uint32_t count) {
  const auto& m = s.mesh;
  std::vector<double> cdf(m.triangles.size());
  double total = 0;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    glm::vec3 a = m.vertices[t.v0].position, b = m.vertices[t.v1].position, c = m.vertices[t.v2].position;
    total += 0.5 * glm::length(glm::cross(b - a, c - a));
    cdf[i] = total;
    lo = glm::min(lo, glm::min(a, glm::min(b, c)));
    hi = glm::max(hi, glm::max(a, glm::max(b, c)));
  }
  float offset = 1e-5f * glm::length(hi - lo);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<TraceRay> rays;
  rays.reserve(count);
  while (rays.size() < count) {
    size_t i = std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin();
    const auto& t = m.triangles[std::min(i, cdf.size() - 1)];
    glm::vec3 a = m.vertices[t.v0].position, b = m.vertices[t.v1].position, c = m.vertices[t.v2].position;
    glm::vec3 n = glm::cross(b - a, c - a);
    if (!(glm::length(n) > 0.0f)) continue;
    n = glm::normalize(n) * (u(rng) < 0.5f ? -1.0f : 1.0f);
    float r1 = u(rng), r2 = u(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    glm::vec3 p = a + r1 * (b - a) + r2 * (c - a);
    glm::vec3 tx = glm::normalize(std::abs(n.x) > 0.9f ? glm::cross(n, glm::vec3(0, 1, 0)) : glm::cross(n, glm::vec3(1, 0, 0)));
    glm::vec3 ty = glm::cross(n, tx);
    float rr = std::sqrt(u(rng)), phi = 6.2831853f * u(rng);
    glm::vec3 d = tx * (rr * std::cos(phi)) + ty * (rr * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1 - rr * rr));
    rays.push_back({p + offset * n, 0.0f, glm::normalize(d), std::numeric_limits<float>::infinity()});
  }
  return rays;
}

// Fraction of rays where `b` agrees with `a`: both miss, the same triangle, or t within `tol`.
double agreement(const std::vector<TraceHit>& a, const std::vector<TraceHit>& b, size_t count, float tol) {
  size_t same = 0;
  for (size_t i = 0; i < count; ++i) {
    bool ma = a[i].triangle == gpu::bvh_trace::kNoHit, mb = b[i].triangle == gpu::bvh_trace::kNoHit;
    if (ma || mb)
      same += ma == mb;
    else
      same += a[i].triangle == b[i].triangle || std::abs(a[i].t - b[i].t) <= tol * std::abs(a[i].t);
  }
  return count ? double(same) / count : 1.0;
}

}  // namespace

int runTrace(const std::vector<std::string>& argv) {
  app::Args args(argv, "trace");
  std::string only = args.value("--scene").value_or("");
  uint32_t triangles = uint32_t(args.integer("--triangles", 1, 1ll << 27).value_or(0));
  uint32_t side = uint32_t(args.integer("--side", 16, 2048).value_or(1024));  // rays = side^2
  int repeat = int(args.integer("--repeat", 1, 100).value_or(3));
  // How traversal reads the BVH (shared/bvh.h); default: the device's choice.
  std::string accessName = args.value("--bvh-access").value_or("auto");
  // Rays per invocation of the batch tracer's pools (bvh::TraceRaysPass::Args::raysPerLane), one
  // timed line each; 1 traces one ray per invocation, as the renderers' kernels do.
  // Default: the pools the pass uses, and one ray per invocation beside them.
  std::vector<uint32_t> raysPerLane = {1u, bvh::TraceRaysPass::Args().raysPerLane};
  if (auto v = args.integerList("--rays-per-lane", 1, 64)) raysPerLane.assign(v->begin(), v->end());
  bvh::GpuBuildOptions buildOptions;
  hierarchyOptions(args, "trace", buildOptions);
  args.finish();
  bvh::Access access = bvh::Access::Auto;
  if (accessName == "storage")
    access = bvh::Access::Storage;
  else if (accessName == "texel")
    access = bvh::Access::TexelFetch;
  else if (accessName != "auto")
    throw InputError("trace: --bvh-access must be auto, storage or texel");
  vk::Context ctx;
  bvh::GpuBuilder builder(ctx, buildOptions);
  bvh::TraceRaysPass pass(ctx, false, access);
  vk::GpuTimer timer(ctx);
  for (const BvhBenchScene& s : bvhBenchScenes(only, triangles)) {
    const auto& m = s.mesh;
    const uint32_t n = uint32_t(m.triangles.size());
    vk::Buffer vertices(ctx, m.vertices.size() * sizeof(gpu::scene::Vertex), vk::MemoryUse::DeviceLocal, "bench vertices");
    vk::Buffer triangles(ctx, m.triangles.size() * sizeof(gpu::scene::Triangle), vk::MemoryUse::DeviceLocal, "bench triangles");
    vertices.uploadVector(m.vertices);
    triangles.uploadVector(m.triangles);
    // Both node forms: the reference hits come from the host tracer, which reads the exact nodes.
    bvh::Bvh tree = builder.build(vertices, triangles, n, nullptr, bvh::NodeForms::Both);
    bvh::HostBvh host = bvh::download(tree);
    auto leaves = tree.leafData.downloadVector<gpu::bvh::BvhLeafTriangle>(tree.triangleCount);
    bvh::HostTracer twin(host, leaves);
#ifdef OSR_HAVE_EMBREE
    EmbreePeer peer(m, 2);
    peer.buildScene();
#endif
    for (const char* kind : {"primary", "diffuse"}) {
      std::vector<TraceRay> rays = std::string(kind) == "primary" ? primaryRays(s, side) : diffuseRays(s, side * side);
      const uint32_t count = uint32_t(rays.size());
      vk::Buffer rayBuf(ctx, count * sizeof(TraceRay), vk::MemoryUse::DeviceLocal, "bench rays");
      vk::Buffer hitBuf(ctx, count * sizeof(TraceHit), vk::MemoryUse::DeviceLocal, "bench hits");
      rayBuf.uploadVector(rays);
      std::vector<TraceHit> expected(std::min<size_t>(count, 20000));
      for (size_t i = 0; i < expected.size(); ++i) expected[i] = twin.closest(rays[i]);
#ifdef OSR_HAVE_EMBREE
      std::vector<TraceHit> peerHits;
      double peerMs = std::numeric_limits<double>::infinity(), peerCpu = peerMs;
      for (int r = 0; r < repeat; ++r) {
        double cpuStart = processCpuMs();
        peerMs = std::min(peerMs, peer.trace(rays, peerHits));
        peerCpu = std::min(peerCpu, processCpuMs() - cpuStart);
      }
#endif
      std::vector<TraceHit> hits;
      for (uint32_t perLane : raysPerLane) {
        double best = std::numeric_limits<double>::infinity(), bestCpu = best;
        for (int r = 0; r <= repeat; ++r) {  // the first warms up, the rest are timed
          double cpuStart = processCpuMs();
          ctx.submitAndWait([&](VkCommandBuffer cmd) {
            timer.reset(cmd);
            vk::TimedScope scope(&timer, cmd, "bvh_trace_rays");
            bvh::TraceRaysPass::Args a;
            a.bvh = &tree;
            a.rays = rayBuf;
            a.hits = hitBuf;
            a.rayCount = count;
            a.raysPerLane = perLane;
            pass.record(cmd, a);
          });
          if (r > 0) best = std::min(best, timer.totalMs("bvh_trace_rays"));
          if (r > 0) bestCpu = std::min(bestCpu, processCpuMs() - cpuStart);
        }
        hits = hitBuf.downloadVector<TraceHit>(count);
        double agree = agreement(expected, hits, expected.size(), 1e-4f);
        if (agree < 0.999) {
          std::fprintf(stderr, "osr-bench trace: %s %s: GPU hits agree with the CPU traversal on only %.4f\n",
                       s.name.c_str(), kind, agree);
          return 1;
        }
        size_t hitCount = 0;
        for (const auto& h : hits) hitCount += h.triangle != gpu::bvh_trace::kNoHit;
        JsonLine line;
        line.str("bench", "trace").str("scene", s.name).integer("triangles", n).str("device", ctx.caps().deviceName);
        line.str("rays", kind).integer("ray_count", count).integer("rays_per_lane", perLane);
        line.str("nodes", tree.quantized ? "quantized" : "exact");  // the node form traversal read
        line.num("mrays_per_s", count / (best * 1e3));
        line.num("ms", best).num("cpu_time_ms", bestCpu).num("hit_fraction", double(hitCount) / count);
#ifdef OSR_HAVE_EMBREE
        line.num("ratio_vs_embree", peerMs / best).num("cpu_time_ratio_vs_embree", peerCpu / bestCpu);
#endif
        line.print();
      }
#ifdef OSR_HAVE_EMBREE
      JsonLine()
          .str("bench", "trace")
          .str("peer", "embree")
          .str("scene", s.name)
          .integer("triangles", n)
          .str("device", "Embree 3 rtcIntersect1 on the CPU, 2 threads")
          .str("rays", kind)
          .integer("ray_count", count)
          .num("mrays_per_s", count / (peerMs * 1e3))
          .num("ms", peerMs)
          .num("cpu_time_ms", peerCpu)
          .num("agree_with_gpu", agreement(peerHits, hits, count, 1e-3f))
          .print();
#endif
    }
  }
  return 0;
}

}  // namespace osr::bench
