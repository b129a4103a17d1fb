// GpuBuilder::build: the device BVH build in named stages (validate, allocate, record the sort,
// the hierarchy and the emit in one command buffer, verify or retry, statistics); the passes are
// src/bvh/<pass>.h, their order and data shaders/shared/bvh_build.h. A readback of one node
// afterwards gives the SAH cost and depth, and checks that every triangle was placed.
#include "bvh/gpu_builder.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "bvh/bounds.h"
#include "bvh/build_scratch.h"
#include "bvh/bvh.h"
#include "bvh/emit.h"
#include "bvh/lbvh.h"
#include "bvh/morton.h"
#include "bvh/ploc.h"
#include "bvh/radix_sort.h"
#include "bvh/refit.h"
#include "bvh/subtree_count.h"
#include "bvh/treelet.h"
#include "common/error.h"

namespace osr::bvh {

namespace bb = gpu::bvh_build;

namespace {

uint32_t ordered(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  return bb::bvhOrderedFromBits(bits);
}

}  // namespace

struct BuildPasses {
  BoundsPass bounds;
  MortonPass morton;
  RadixSort sort;
  LbvhPass lbvh;
  RefitPass refit;
  TreeletPass treelet;
  SubtreeCountPass subtreeCount;
  EmitPass emit;
  std::unique_ptr<PlocPass> ploc;  // bindings only (plocFor); made on the first PLOC build
  BuildPasses(const vk::Context& ctx, uint32_t treeletLeaves, bool byAddress)
      : bounds(ctx, byAddress),
        morton(ctx, byAddress),
        sort(ctx),
        lbvh(ctx, byAddress),
        refit(ctx, byAddress),
        treelet(ctx, treeletLeaves, byAddress),
        subtreeCount(ctx, byAddress),
        emit(ctx, byAddress) {}
};

// One build's buffers and views, as the stages below hand them to the passes. It points into
// itself (arrays at bvh's buffers), so it stays where it was made.
struct BuildResources {
  BuildResources(const vk::Context& ctx, const BuildScratch& sc, const vk::Buffer& vertices,
                 const vk::Buffer& triangles, uint32_t n, NodeForms forms);
  BuildResources(const BuildResources&) = delete;
  BuildResources& operator=(const BuildResources&) = delete;
  const uint32_t n, interiorCount;
  const BuildScratch& scratch;
  Bvh bvh;  // the result
  BuildTexelViews texels;
  // The scene's triangles and vertices through texel views where their buffers allow them
  // (gpu::GpuScene's do) and the views reach their ends: bvh_bounds then gathers instead of
  // looping over the lanes per load.
  vk::BufferView triangleTexels, vertexTexels;
  BuildArrayBuffers arrays;
  // The sort's temporary arrays (uint per triangle) are free once it is done: they hold the
  // subtree node counts (from PLOC on) and positions; its keys hold the leaf bases of the
  // depth-first order after the hierarchy is made.
  vk::BufferRange subtreeNodes, positions, leafBases;
  bool byAddress = false;              // arrays past one binding: passes that read them by address
  BuildPasses* passes = nullptr;       // of byAddress
  std::optional<PlocPass::Args> ploc;  // where the build may use PLOC (plocFor)
  uint64_t plocScratchBytes = 0;
};

BuildResources::BuildResources(const vk::Context& ctx, const BuildScratch& sc,
                               const vk::Buffer& vertices, const vk::Buffer& triangles,
                               uint32_t triangleCount, NodeForms forms)
    : n(triangleCount), interiorCount(std::max<uint32_t>(triangleCount - 1, 1)), scratch(sc) {
  const uint64_t nodeBytes = sizeof(bb::BvhBuildNode);
  bvh.nodeCount = interiorCount;
  bvh.triangleCount = n;
  bvh.quantized = quantizedTraversal(bvh.triangleCount);
  bvh.hasExactNodes = forms == NodeForms::Both || !bvh.quantized;
  bvh.hasQuantizedNodes = forms == NodeForms::Both || bvh.quantized;
  // An unwritten form keeps one node of memory: its binding must still be valid.
  const uint32_t exactNodes = bvh.hasExactNodes ? interiorCount : 1,
                 quantizedNodes = bvh.hasQuantizedNodes ? interiorCount : 1;
  bvh.nodes = vk::Buffer(ctx, uint64_t(exactNodes) * sizeof(gpu::bvh::BvhNode),
                         vk::MemoryUse::DeviceLocal, "bvh nodes", Bvh::kExtraUsage);
  bvh.traversalNodes =
      vk::Buffer(ctx, uint64_t(quantizedNodes) * sizeof(gpu::bvh::BvhTraversalNode),
                 vk::MemoryUse::DeviceLocal, "bvh traversal nodes", Bvh::kExtraUsage);
  bvh.leafData = vk::Buffer(ctx, uint64_t(n) * sizeof(gpu::bvh::BvhLeafTriangle),
                            vk::MemoryUse::DeviceLocal, "bvh leaf triangles", Bvh::kExtraUsage);
  bvh.makeTexelViews(ctx);
  // bvh_emit_leaves writes every leaf entry, scattered, from every device thread: populated here
  // first, the pass runs faster and steadier (docs/bvh.md). The node arrays are written in order
  // and only in part: populating them gained nothing, nor did populating the scratch buffers of
  // a first build (which costs more).
  bvh.leafData.prefault(bvh.leafData.size());

  texels.interior = sc.interiorTexels.handle();
  texels.leaves = sc.leafTexels.handle();
  texels.prims = sc.primTexels.handle();
  constexpr VkBufferUsageFlags kTexelUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  if ((triangles.usage() & kTexelUsage) && (vertices.usage() & kTexelUsage)) {
    bool coversT = false, coversV = false;
    triangleTexels =
        vk::BufferView::uintTexels(ctx, triangles, "bvh scene triangle texels", &coversT);
    vertexTexels = vk::BufferView::uintTexels(ctx, vertices, "bvh scene vertex texels", &coversV);
    if (!coversT || !coversV) triangleTexels = vk::BufferView(), vertexTexels = vk::BufferView();
  }
  arrays.triangles = vk::BufferRange(triangles, 0, uint64_t(n) * sizeof(gpu::scene::Triangle));
  arrays.vertices = vertices;
  arrays.prims = vk::BufferRange(sc.prims, 0, uint64_t(n) * sizeof(gpu::bvh::BvhLeafTriangle));
  arrays.interior = vk::BufferRange(sc.interior, 0, interiorCount * nodeBytes);
  arrays.leaves = vk::BufferRange(sc.leaves, 0, n * nodeBytes);
  arrays.nodes = bvh.nodes;
  arrays.leafTriangles = bvh.leafData;
  arrays.traversalNodes = bvh.traversalNodes;
  byAddress = arrays.pastOneBinding(ctx);
  subtreeNodes = vk::BufferRange(sc.keysTmp, 0, 4ull * interiorCount);
  positions = vk::BufferRange(sc.valuesTmp, 0, 4ull * interiorCount);
  leafBases = vk::BufferRange(sc.keys, 0, 4ull * interiorCount);
}

namespace {

// How one recording makes the hierarchy: by PLOC, then one treelet round over the upper tree,
// where its greedy merges are weakest; or by LBVH, then treelet rounds.
struct HierarchyPlan {
  bool ploc = false;
  // LBVH: round r restructures the nodes of at least treeletMinTriangles << r triangles.
  uint32_t treeletRounds = 0, treeletMinTriangles = 0;
  // PLOC: its iterations, and its treelet round's smallest subtree (0: no round).
  PlocPass::Iterations plocIterations;
  uint32_t plocTreeletMinTriangles = 0;
};

// What the readback of a complete tree says.
struct BuiltTree {
  bb::BvhBuildNode root{};
  uint32_t height = 0, plocIterations = 0;
};

// Stage 1: the scene is one the device can build.
void validate(const vk::Context& ctx, const vk::Buffer& triangles, uint32_t n) {
  if (n == 0) throw InputError("bvh: a scene with no triangles has no BVH");
  const TriangleLimit limit = triangleLimit(ctx);
  if (n > limit.triangles)
    throw DeviceError("bvh: " + std::to_string(n) + " triangles exceed the device's limit of " +
                      std::to_string(limit.triangles) + " (" + limit.limit + ", " +
                      ctx.caps().deviceName + ")");
  if (triangles.size() < uint64_t(n) * sizeof(gpu::scene::Triangle))
    throw DeviceError("bvh: triangle buffer '" + triangles.name() + "' holds fewer than " +
                      std::to_string(n) + " triangles");
}

// PLOC's arguments over the build's arrays and PLOC's scratch `ps`.
PlocPass::Args plocArgs(const vk::Context& ctx, const GpuBuildOptions& options,
                        const BuildResources& res, const PlocScratch& ps) {
  const uint32_t n = res.n;
  PlocPass::Args a;
  a.arrays = &res.arrays;
  a.texels = &res.texels;
  a.values = vk::BufferRange(res.scratch.values, 0, 4ull * n);
  for (int k = 0; k < 2; ++k) {
    a.clusters[k] = &ps.clusters[k];
    a.clusterTexels[k] = ps.clusterTexels[k].handle();
  }
  a.nearest = vk::BufferRange(ps.nearest, 0, 4ull * n);
  a.partials = ps.partials;
  a.pairs = ps.pairs;
  a.nearestTexels = ps.nearestTexels.handle();
  a.subtreeNodes = res.subtreeNodes;
  a.subtreeNodeTexels = res.scratch.keyTmpTexels.handle();
  a.state = &ps.state;
  a.triangleCount = n;
  a.localRounds = PlocPass::localMergesSupported(ctx) ? options.plocLocalRounds : 0;
  a.tailClusters = options.plocTailClusters;  // PlocPass refuses more than its tail holds
  a.tailCapacity = PlocScratch::tailCapacity(n);
  a.tailScratch = vk::BufferRange(ps.tail, 0, 64ull * a.tailCapacity);
  return a;
}

HierarchyPlan firstPlan(const GpuBuildOptions& options, const BuildResources& res) {
  HierarchyPlan plan;
  plan.ploc = plocFor(options, res.n, !res.byAddress);
  plan.treeletRounds = treeletRoundsFor(options, res.n);
  plan.treeletMinTriangles = options.treeletMinTriangles;
  if (plan.ploc) {
    plan.plocIterations = PlocPass::Iterations(res.n, res.ploc->tailClusters);
    plan.plocTreeletMinTriangles = res.n > 2 ? options.plocTreeletMinTriangles : 0;
  }
  return plan;
}

// Stage 3a: the triangles' bounds and Morton codes, sorted.
void recordSort(VkCommandBuffer cmd, const BuildResources& res, vk::GpuTimer& timer) {
  const BuildScratch& sc = res.scratch;
  bb::BvhBuildInfo initial{};
  const float kBig = 3.0e38f;
  initial.centroidMin = glm::uvec4(ordered(kBig), ordered(kBig), ordered(kBig), 0);
  initial.centroidMax = glm::uvec4(ordered(-kBig), ordered(-kBig), ordered(-kBig), 0);
  vkCmdUpdateBuffer(cmd, sc.info.handle(), 0, sizeof(initial), &initial);
  vk::transferBarrier(cmd);
  BuildPasses& passes = *res.passes;
  {
    vk::TimedScope scope(&timer, cmd, "bvh_bounds");
    passes.bounds.record(cmd, {&res.arrays, sc.info, res.n, res.triangleTexels.handle(),
                               res.vertexTexels.handle(), res.texels.prims});
  }
  {
    vk::TimedScope scope(&timer, cmd, "bvh_morton");
    passes.morton.record(cmd, {&res.arrays, &res.texels, sc.info, sc.keys, sc.values, res.n});
  }
  passes.sort.record(cmd,
                     {sc.keys, sc.values, sc.keysTmp, sc.valuesTmp, sc.hist, sc.partials, res.n,
                      sc.keyTexels.handle(), sc.valueTexels.handle(), sc.keyTmpTexels.handle(),
                      sc.valueTmpTexels.handle()},
                     &timer);
}

// A treelet round over the nodes of at least minTriangles triangles; after PLOC it keeps the
// subtree node counts that PLOC's merges made, so no bvh_subtree_count.
void recordTreelets(VkCommandBuffer cmd, const BuildResources& res, uint32_t minTriangles,
                    bool afterPloc, vk::GpuTimer& timer) {
  const BuildScratch& sc = res.scratch;
  TreeletPass::Args a{&res.arrays, &res.texels, sc.counters, &sc.schedule, sc.nodeList};
  a.triangleCount = res.n;
  a.minTriangles = minTriangles;
  a.subtreeNodes = res.subtreeNodes;
  a.subtreeNodeTexels = sc.keyTmpTexels.handle();
  a.countNodes = afterPloc;
  res.passes->treelet.record(cmd, a, &timer);
}

// Stage 3b: the hierarchy over the sorted triangles, with its subtree node counts.
void recordHierarchy(VkCommandBuffer cmd, const BuildResources& res, const HierarchyPlan& plan,
                     vk::GpuTimer& timer) {
  BuildPasses& passes = *res.passes;
  const uint32_t n = res.n;
  if (plan.ploc) {
    passes.ploc->record(cmd, *res.ploc, plan.plocIterations.count(), &timer);
    if (plan.plocTreeletMinTriangles != 0)
      recordTreelets(cmd, res, plan.plocTreeletMinTriangles, true, timer);
    return;
  }
  const BuildScratch& sc = res.scratch;
  {
    vk::TimedScope scope(&timer, cmd, "bvh_lbvh");
    passes.lbvh.record(cmd,
                       {&res.arrays, &res.texels, sc.keys, sc.values, sc.keyTexels.handle(), n});
  }
  if (n > 1) {
    vk::TimedScope scope(&timer, cmd, "bvh_refit");
    passes.refit.record(cmd, {&res.arrays, &res.texels, &sc.counters, n});
  }
  for (uint32_t round = 0; round < plan.treeletRounds && n > 2; ++round) {
    // Karras & Aila grow the smallest restructured subtree each round: the bottom levels
    // improve most in the first round, later rounds polish the upper tree at less cost.
    recordTreelets(cmd, res, plan.treeletMinTriangles << round, false, timer);
  }
  if (n > 1) {
    vk::TimedScope scope(&timer, cmd, "bvh_subtree_count");
    passes.subtreeCount.record(cmd, {&res.arrays, &res.texels, sc.counters, res.subtreeNodes, n});
  }
}

// Stage 4: the traversal nodes (the forms res.bvh holds) and leaf triangles.
void recordEmit(VkCommandBuffer cmd, const BuildResources& res, vk::GpuTimer& timer) {
  const BuildScratch& sc = res.scratch;
  EmitPass::Args emit{&res.arrays, &res.texels, sc.info, sc.counters, sc.slotTexels.handle()};
  emit.subtreeNodes = res.subtreeNodes;
  emit.positions = res.positions;
  emit.levelNodes = sc.nodeList;
  emit.leafBases = res.leafBases;
  emit.schedule = &sc.schedule;
  emit.triangleCount = res.n;
  emit.exactNodes = res.bvh.hasExactNodes;
  emit.quantizedNodes = res.bvh.hasQuantizedNodes;
  res.passes->emit.record(cmd, emit, &timer);
}

// Stage 5: reads back the recorded tree. Returns it where it is complete and within
// kBvhMaxDepth; otherwise sets `plan` to what the next recording builds and returns nothing.
std::optional<BuiltTree> verifyOrRetry(const BuildResources& res, HierarchyPlan& plan) {
  const uint32_t n = res.n;
  BuiltTree tree;
  if (plan.ploc) {
    const PlocPass::Result ploc = PlocPass::result(*res.ploc, plan.plocIterations.count());
    if (!plan.plocIterations.complete(ploc.clustersLeft)) return std::nullopt;
    tree.plocIterations = ploc.iterationsMerged;
  }
  const BuildScratch& sc = res.scratch;
  tree.root = n > 1 ? sc.interior.downloadVector<bb::BvhBuildNode>(1)[0]
                    : sc.leaves.downloadVector<bb::BvhBuildNode>(1)[0];
  const bb::BvhBuildInfo info = sc.info.downloadVector<bb::BvhBuildInfo>(1)[0];
  tree.height = n > 1 ? (tree.root.flags >> bb::kTraversalHeightShift) & bb::kHeightMask : 1;
  // The LBVH alone has at most 30 + ceil(log2 N) + 1 <= 58 levels (N <= 2^27, the leaf index
  // field); restructuring or PLOC can deepen it, so a tree past the traversal bound is rebuilt
  // as a plain LBVH.
  if (tree.height > gpu::bvh::kBvhMaxDepth) {
    if (plan.ploc || plan.treeletRounds != 0) {
      plan.ploc = false;
      plan.treeletRounds = 0;
      return std::nullopt;
    }
    throw DeviceError("bvh: tree depth " + std::to_string(tree.height) + " exceeds kBvhMaxDepth");
  }
  if (info.leafCounter != n)
    throw DeviceError("bvh: GPU build placed " + std::to_string(info.leafCounter) + " of " +
                      std::to_string(n) + " triangles");
  return tree;
}

// Stage 6: the statistics of the build that made `tree` by `plan`.
BuildStats buildStats(const BuildResources& res, const HierarchyPlan& plan, const BuiltTree& tree,
                      const vk::GpuTimer& timer) {
  BuildStats stats;
  stats.depth = tree.height;
  stats.treeletRounds =
      plan.ploc ? (plan.plocTreeletMinTriangles != 0 ? 1 : 0) : plan.treeletRounds;
  stats.plocIterations = plan.ploc ? tree.plocIterations : 0;
  stats.plocLocalRounds = plan.ploc ? res.ploc->localRounds : 0;
  stats.plocTailClusters = plan.ploc ? res.ploc->tailClusters : 0;
  for (const vk::PassTime& p : timer.results()) {
    auto it = std::find_if(stats.passes.begin(), stats.passes.end(),
                           [&](const vk::PassTime& q) { return q.name == p.name; });
    if (it == stats.passes.end())
      stats.passes.push_back(p);
    else
      it->ms += p.ms;
    stats.totalMs += p.ms;
  }
  const bb::BvhBuildNode& root = tree.root;
  glm::vec3 d = root.hi - root.lo;
  double area = 2.0 * (double(d.x) * d.y + double(d.y) * d.z + double(d.z) * d.x);
  // One triangle: the root node over a single leaf (root.cost is that leaf's).
  double cost = res.n > 1 ? root.cost : gpu::bvh::kSahNodeCost * area + root.cost;
  stats.sahCost = area > 0 ? cost / area : 0.0;
  stats.scratchBytes = res.scratch.bytes + (plan.ploc ? res.plocScratchBytes : 0);
  return stats;
}

}  // namespace

Bvh buildGpu(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
             uint32_t triangleCount, BuildStats* stats) {
  return GpuBuilder(ctx).build(vertices, triangles, triangleCount, stats);
}

Bvh buildGpu(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
             uint32_t triangleCount, const GpuBuildOptions& options, BuildStats* stats,
             NodeForms forms) {
  return GpuBuilder(ctx, options).build(vertices, triangles, triangleCount, stats, forms);
}

GpuBuilder::GpuBuilder(const vk::Context& ctx, const GpuBuildOptions& options)
    : ctx_(ctx),
      options_(options),
      passes_(std::make_unique<BuildPasses>(ctx, options.treeletLeaves, false)) {}

GpuBuilder::~GpuBuilder() = default;

// Stage 2: the scratch (grown where too small), the build's resources over it, and the passes
// for the way they reach the arrays; PLOC's pass, scratch and arguments where it may build.
std::unique_ptr<BuildResources> GpuBuilder::allocate(const vk::Buffer& vertices,
                                                     const vk::Buffer& triangles, uint32_t n,
                                                     NodeForms forms) const {
  const vk::Context& ctx = ctx_;
  if (!scratch_ || scratch_->capacity < n) {
    scratch_.reset();  // before the next allocation: at most one set of scratch exists
    scratch_ = std::make_unique<BuildScratch>(ctx, n);
  }
  auto resources = std::make_unique<BuildResources>(ctx, *scratch_, vertices, triangles, n, forms);
  BuildResources& res = *resources;
  // Past one binding, pipelines that reach the arrays by address (made on first need: on
  // lavapipe an address load costs about twice a binding's, lib/bvh_build_arrays.glsl).
  if (res.byAddress && !ctx.caps().bufferDeviceAddress)
    throw DeviceError("bvh: " + std::to_string(n) +
                      " triangles need arrays past maxStorageBufferRange (" +
                      std::to_string(ctx.caps().maxStorageBufferRange >> 20) +
                      " MiB), read by device address, which \"" + ctx.caps().deviceName +
                      "\" lacks (bufferDeviceAddress)");
  if (res.byAddress && !addressPasses_)
    addressPasses_ = std::make_unique<BuildPasses>(ctx, options_.treeletLeaves, true);
  res.passes = res.byAddress ? addressPasses_.get() : passes_.get();
  if (!plocFor(options_, n, !res.byAddress)) return resources;
  if (!res.passes->ploc) res.passes->ploc = std::make_unique<PlocPass>(ctx);
  if (!plocScratch_ || plocScratch_->capacity < n) {
    plocScratch_.reset();
    plocScratch_ = std::make_unique<PlocScratch>(ctx, n);
  }
  res.ploc = plocArgs(ctx, options_, res, *plocScratch_);
  res.plocScratchBytes = plocScratch_->bytes;
  return resources;
}

Bvh GpuBuilder::build(const vk::Buffer& vertices, const vk::Buffer& triangles,
                      uint32_t triangleCount, BuildStats* stats, NodeForms forms) const {
  validate(ctx_, triangles, triangleCount);
  const std::unique_ptr<BuildResources> resources =
      allocate(vertices, triangles, triangleCount, forms);
  BuildResources& res = *resources;
  HierarchyPlan plan = firstPlan(options_, res);
  vk::GpuTimer timer(ctx_, 256);
  std::optional<BuiltTree> tree;
  while (!tree) {
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      timer.reset(cmd);
      recordSort(cmd, res, timer);
      recordHierarchy(cmd, res, plan, timer);
      recordEmit(cmd, res, timer);
    });
    tree = verifyOrRetry(res, plan);
  }
  if (stats) *stats = buildStats(res, plan, *tree, timer);
  return std::move(res.bvh);
}

}  // namespace osr::bvh
