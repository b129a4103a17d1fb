// buildGpu: the dispatch sequence of the device BVH build (shaders/shared/bvh_build.h lists the
// passes). One command buffer, timed per pass; a readback of one node afterwards gives the SAH
// cost and depth, and checks that every triangle was placed.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "bvh/build_passes.h"
#include "bvh/bvh.h"
#include "bvh/gpu_builder.h"
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

struct GpuBuilder::Passes {
  BoundsPass bounds;
  MortonPass morton;
  RadixSort sort;
  LbvhPass lbvh;
  RefitPass refit;
  TreeletPass treelet;
  SubtreeCountPass subtreeCount;
  EmitPass emit;
  std::unique_ptr<PlocPass> ploc;  // bindings only (plocFor); made on the first PLOC build
  Passes(const vk::Context& ctx, uint32_t treeletLeaves, bool byAddress)
      : bounds(ctx, byAddress), morton(ctx, byAddress), sort(ctx), lbvh(ctx, byAddress), refit(ctx, byAddress),
        treelet(ctx, treeletLeaves, byAddress), subtreeCount(ctx, byAddress), emit(ctx, byAddress) {}
};

namespace {

vk::Buffer scratch(const vk::Context& ctx, uint64_t bytes, const char* name, VkBufferUsageFlags extraUsage = 0) {
  return vk::Buffer(ctx, std::max<uint64_t>(bytes, 16), vk::MemoryUse::DeviceLocal, name, extraUsage);
}

}  // namespace

// The build's scratch buffers for up to `capacity` triangles, and their views. A builder keeps
// them for its next build: on a CPU device fresh memory is faulted in on first touch, which
// measured about a quarter of a 1M-triangle build's CPU time (huge pages included).
struct GpuBuilder::Scratch {
  uint32_t capacity;
  vk::Buffer prims, info, keys, keysTmp, values, valuesTmp, hist, partials, interior, leaves, counters, schedule,
      nodeList;
  // Of keys, values and their scratch twins for the sort; keys (where the sort leaves them) also
  // for bvh_lbvh.
  vk::BufferView keyTexels, valueTexels, keyTmpTexels, valueTmpTexels;
  vk::BufferView interiorTexels, leafTexels, primTexels, slotTexels;
  uint64_t bytes = 0;

  Scratch(const vk::Context& ctx, uint32_t n) : capacity(n) {
    const uint32_t interiorCount = std::max<uint32_t>(n - 1, 1);
    const uint64_t nodeBytes = sizeof(bb::BvhBuildNode);
    const uint64_t histBytes = RadixSort::histogramBytes(n);
    prims = scratch(ctx, uint64_t(n) * sizeof(gpu::bvh::BvhLeafTriangle), "bvh prims", BuildTexelViews::kUsage);
    info = scratch(ctx, sizeof(bb::BvhBuildInfo), "bvh build info");
    keys = scratch(ctx, 4ull * n, "bvh keys", RadixSort::kUsage);
    keysTmp = scratch(ctx, 4ull * n, "bvh keys tmp", RadixSort::kUsage);
    values = scratch(ctx, 4ull * n, "bvh values", RadixSort::kUsage);
    valuesTmp = scratch(ctx, 4ull * n, "bvh values tmp", RadixSort::kUsage);
    hist = scratch(ctx, histBytes, "bvh radix histogram");
    partials = scratch(ctx, ExclusiveScan::partialsBytes(uint32_t(histBytes / 4)), "bvh scan partials");
    interior = scratch(ctx, interiorCount * nodeBytes, "bvh build interior", BuildTexelViews::kUsage);
    leaves = scratch(ctx, n * nodeBytes, "bvh build leaves", BuildTexelViews::kUsage);
    // Climb counters of bvh_refit and bvh_subtree_count, then slots of the emit passes.
    counters = scratch(ctx, 4ull * interiorCount, "bvh climb counters", EmitPass::kSlotsUsage);
    // The treelet rounds' schedule, then the emit's (by depth).
    schedule = scratch(ctx, std::max(TreeletPass::scheduleBytes(), EmitPass::scheduleBytes()), "bvh level schedule");
    // Node lists of the treelet rounds, then of the emit's depths.
    nodeList = scratch(ctx, 4ull * interiorCount, "bvh node list");
    for (const vk::Buffer* b : {&prims, &info, &keys, &keysTmp, &values, &valuesTmp, &hist, &partials, &interior,
                                &leaves, &counters, &schedule, &nodeList})
      bytes += b->size();
    keyTexels = vk::BufferView::uintWords(ctx, keys, "bvh key texels");
    valueTexels = vk::BufferView::uintWords(ctx, values, "bvh value texels");
    keyTmpTexels = vk::BufferView::uintWords(ctx, keysTmp, "bvh key tmp texels");
    valueTmpTexels = vk::BufferView::uintWords(ctx, valuesTmp, "bvh value tmp texels");
    interiorTexels = vk::BufferView::uintTexels(ctx, interior, "bvh interior texels");
    leafTexels = vk::BufferView::uintTexels(ctx, leaves, "bvh leaf texels");
    primTexels = vk::BufferView::uintTexels(ctx, prims, "bvh prim texels");
    slotTexels = vk::BufferView::uintWords(ctx, counters, "bvh emit slot texels");
  }
};

// PLOC's scratch (PlocPass::Args) for up to `capacity` triangles, kept like Scratch.
struct GpuBuilder::PlocScratch {
  uint32_t capacity;
  vk::Buffer clusters[2], nearest, partials, pairs, state, tail;
  vk::BufferView clusterTexels[2], nearestTexels;
  uint64_t bytes = 0;
  static uint32_t tailCapacity(uint32_t n) { return std::min(n, bb::kPlocTailCapacity); }
  PlocScratch(const vk::Context& ctx, uint32_t n) : capacity(n) {
    for (int k = 0; k < 2; ++k) {
      clusters[k] = scratch(ctx, 32ull * n, "bvh ploc clusters", PlocPass::kClusterUsage);
      clusterTexels[k] = vk::BufferView::uintTexels(ctx, clusters[k], "bvh ploc cluster texels");
    }
    nearest = scratch(ctx, 4ull * n, "bvh ploc nearest", PlocPass::kClusterUsage);
    nearestTexels = vk::BufferView::uintWords(ctx, nearest, "bvh ploc nearest texels");
    partials = scratch(ctx, 8ull * (n + bb::kWorkgroupSize), "bvh ploc partials");
    pairs = scratch(ctx, 16ull * (n / 2 + 1), "bvh ploc pairs");
    state = scratch(ctx, sizeof(bb::PlocState), "bvh ploc state", PlocPass::kStateUsage);
    tail = scratch(ctx, 64ull * tailCapacity(n), "bvh ploc tail clusters");
    for (const vk::Buffer* b : {&clusters[0], &clusters[1], &nearest, &partials, &pairs, &state, &tail}) bytes += b->size();
  }
};

Bvh buildGpu(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
             uint32_t triangleCount, BuildStats* stats) {
  return GpuBuilder(ctx).build(vertices, triangles, triangleCount, stats);
}

Bvh buildGpu(const vk::Context& ctx, const vk::Buffer& vertices, const vk::Buffer& triangles,
             uint32_t triangleCount, const GpuBuildOptions& options, BuildStats* stats, NodeForms forms) {
  return GpuBuilder(ctx, options).build(vertices, triangles, triangleCount, stats, forms);
}

GpuBuilder::GpuBuilder(const vk::Context& ctx, const GpuBuildOptions& options)
    : ctx_(ctx), options_(options), passes_(std::make_unique<Passes>(ctx, options.treeletLeaves, false)) {}

GpuBuilder::~GpuBuilder() = default;

Bvh GpuBuilder::build(const vk::Buffer& vertices, const vk::Buffer& triangles,
                      uint32_t triangleCount, BuildStats* stats, NodeForms forms) const {
  const vk::Context& ctx = ctx_;
  const GpuBuildOptions& options = options_;
  const uint32_t n = triangleCount;
  if (n == 0) throw InputError("bvh: a scene with no triangles has no BVH");
  const TriangleLimit limit = triangleLimit(ctx);
  if (n > limit.triangles)
    throw DeviceError("bvh: " + std::to_string(n) + " triangles exceed the device's limit of " +
                      std::to_string(limit.triangles) + " (" + limit.limit + ", " + ctx.caps().deviceName + ")");
  if (triangles.size() < uint64_t(n) * sizeof(gpu::scene::Triangle))
    throw DeviceError("bvh: triangle buffer '" + triangles.name() + "' holds fewer than " +
                      std::to_string(n) + " triangles");
  const uint32_t interiorCount = std::max<uint32_t>(n - 1, 1);
  const uint64_t nodeBytes = sizeof(bb::BvhBuildNode);

  if (!scratch_ || scratch_->capacity < n) {
    scratch_.reset();  // before the next allocation: at most one set of scratch exists
    scratch_ = std::make_unique<Scratch>(ctx, n);
  }
  const Scratch& sc = *scratch_;
  const uint64_t scratchBytes = sc.bytes;
  const vk::Buffer &info = sc.info, &keys = sc.keys, &keysTmp = sc.keysTmp, &values = sc.values,
                   &valuesTmp = sc.valuesTmp, &hist = sc.hist, &partials = sc.partials, &interior = sc.interior,
                   &leaves = sc.leaves, &counters = sc.counters, &schedule = sc.schedule, &nodeList = sc.nodeList;

  Bvh bvh;
  bvh.nodeCount = interiorCount;
  bvh.triangleCount = n;
  bvh.quantized = quantizedTraversal(bvh.triangleCount);
  bvh.hasExactNodes = forms == NodeForms::Both || !bvh.quantized;
  bvh.hasQuantizedNodes = forms == NodeForms::Both || bvh.quantized;
  // An unwritten form keeps one node of memory: its binding must still be valid.
  const uint32_t exactNodes = bvh.hasExactNodes ? interiorCount : 1, quantizedNodes = bvh.hasQuantizedNodes ? interiorCount : 1;
  bvh.nodes = vk::Buffer(ctx, uint64_t(exactNodes) * sizeof(gpu::bvh::BvhNode), vk::MemoryUse::DeviceLocal, "bvh nodes", Bvh::kExtraUsage);
  bvh.traversalNodes = vk::Buffer(ctx, uint64_t(quantizedNodes) * sizeof(gpu::bvh::BvhTraversalNode), vk::MemoryUse::DeviceLocal, "bvh traversal nodes", Bvh::kExtraUsage);
  bvh.leafData = vk::Buffer(ctx, uint64_t(n) * sizeof(gpu::bvh::BvhLeafTriangle), vk::MemoryUse::DeviceLocal, "bvh leaf triangles", Bvh::kExtraUsage);
  bvh.makeTexelViews(ctx);
  // bvh_emit_leaves writes every leaf entry, scattered, from both of lavapipe's threads: its
  // first-touch faults made the pass take 27 to 68 ms on the 1M-triangle bench mesh (bimodal),
  // against 23-27 ms after the kernel has populated the memory here (docs/bvh.md, "Seventh
  // session"). The node arrays are written in order and only in part: populating them gained
  // nothing, nor did populating the scratch buffers of a first build (which costs more).
  bvh.leafData.prefault(bvh.leafData.size());

  BuildTexelViews texels;
  texels.interior = sc.interiorTexels.handle();
  texels.leaves = sc.leafTexels.handle();
  texels.prims = sc.primTexels.handle();
  // The scene's triangles and vertices through texel views where their buffers allow them
  // (gpu::GpuScene's do) and the views reach their ends: bvh_bounds then gathers instead of
  // looping over the lanes per load.
  vk::BufferView triangleTexels, vertexTexels;
  constexpr VkBufferUsageFlags kTexelUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  if ((triangles.usage() & kTexelUsage) && (vertices.usage() & kTexelUsage)) {
    bool coversT = false, coversV = false;
    triangleTexels = vk::BufferView::uintTexels(ctx, triangles, "bvh scene triangle texels", &coversT);
    vertexTexels = vk::BufferView::uintTexels(ctx, vertices, "bvh scene vertex texels", &coversV);
    if (!coversT || !coversV) triangleTexels = vk::BufferView(), vertexTexels = vk::BufferView();
  }
  BuildArrayBuffers arrays;
  arrays.triangles = vk::BufferRange(triangles, 0, uint64_t(n) * sizeof(gpu::scene::Triangle));
  arrays.vertices = vertices;
  arrays.prims = vk::BufferRange(sc.prims, 0, uint64_t(n) * sizeof(gpu::bvh::BvhLeafTriangle));
  arrays.interior = vk::BufferRange(sc.interior, 0, interiorCount * nodeBytes);
  arrays.leaves = vk::BufferRange(sc.leaves, 0, n * nodeBytes);
  arrays.nodes = bvh.nodes;
  arrays.leafTriangles = bvh.leafData;
  arrays.traversalNodes = bvh.traversalNodes;
  // Past one binding, pipelines that reach the arrays by address (made on first need: on
  // lavapipe an address load costs about twice a binding's, lib/bvh_build_arrays.glsl).
  const bool byAddress = arrays.pastOneBinding(ctx);
  if (byAddress && !ctx.caps().bufferDeviceAddress)
    throw DeviceError("bvh: " + std::to_string(n) + " triangles need arrays past maxStorageBufferRange (" +
                      std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB), read by device address, which \"" +
                      ctx.caps().deviceName + "\" lacks (bufferDeviceAddress)");
  if (byAddress && !addressPasses_) addressPasses_ = std::make_unique<Passes>(ctx, options.treeletLeaves, true);
  Passes& passes = byAddress ? *addressPasses_ : *passes_;

  vk::GpuTimer timer(ctx, 256);
  bb::BvhBuildInfo initial{};
  const float kBig = 3.0e38f;
  initial.centroidMin = glm::uvec4(ordered(kBig), ordered(kBig), ordered(kBig), 0);
  initial.centroidMax = glm::uvec4(ordered(-kBig), ordered(-kBig), ordered(-kBig), 0);

  // The sort's temporary arrays (uint per triangle) are free once it is done: they hold the
  // subtree node counts (from PLOC on) and positions; its keys hold the leaf bases of the
  // depth-first order after the hierarchy is made.
  const vk::BufferRange subtreeNodes(keysTmp, 0, 4ull * interiorCount), positions(valuesTmp, 0, 4ull * interiorCount);
  bool usePloc = plocFor(options, n, !byAddress);
  const uint32_t plocLocalRounds = PlocPass::localMergesSupported(ctx) ? options.plocLocalRounds : 0;
  const uint32_t plocTailClusters = options.plocTailClusters;  // PlocPass refuses more than its tail holds
  const bool plocTreelets = options.plocTreeletMinTriangles != 0 && n > 2;
  auto plocArgs = [&]() {
    if (!passes.ploc) passes.ploc = std::make_unique<PlocPass>(ctx);
    if (!plocScratch_ || plocScratch_->capacity < n) {
      plocScratch_.reset();
      plocScratch_ = std::make_unique<PlocScratch>(ctx, n);
    }
    const PlocScratch& ps = *plocScratch_;
    PlocPass::Args a;
    a.arrays = &arrays;
    a.texels = &texels;
    a.values = vk::BufferRange(values, 0, 4ull * n);
    for (int k = 0; k < 2; ++k) {
      a.clusters[k] = &ps.clusters[k];
      a.clusterTexels[k] = ps.clusterTexels[k].handle();
    }
    a.nearest = vk::BufferRange(ps.nearest, 0, 4ull * n);
    a.partials = ps.partials;
    a.pairs = ps.pairs;
    a.nearestTexels = ps.nearestTexels.handle();
    a.subtreeNodes = subtreeNodes;
    a.subtreeNodeTexels = sc.keyTmpTexels.handle();
    a.state = &ps.state;
    a.triangleCount = n;
    a.localRounds = plocLocalRounds;
    a.tailClusters = plocTailClusters;
    a.tailCapacity = PlocScratch::tailCapacity(n);
    a.tailScratch = vk::BufferRange(ps.tail, 0, 64ull * a.tailCapacity);
    return a;
  };

  // A treelet round over the nodes of at least minTriangles triangles; after PLOC it keeps the
  // subtree node counts that PLOC's merges made, so no bvh_subtree_count.
  auto treeletArgs = [&](uint32_t minTriangles) {
    TreeletPass::Args a{&arrays, &texels, counters, &schedule, nodeList, n, minTriangles};
    a.subtreeNodes = subtreeNodes;
    a.subtreeNodeTexels = sc.keyTmpTexels.handle();
    a.countNodes = usePloc;
    return a;
  };
  auto record = [&](VkCommandBuffer cmd, uint32_t treeletRounds, uint32_t plocIterations) {
    timer.reset(cmd);
    vkCmdUpdateBuffer(cmd, info.handle(), 0, sizeof(initial), &initial);
    vk::transferBarrier(cmd);
    {
      vk::TimedScope scope(&timer, cmd, "bvh_bounds");
      passes.bounds.record(cmd, {&arrays, info, n, triangleTexels.handle(), vertexTexels.handle(), texels.prims});
    }
    {
      vk::TimedScope scope(&timer, cmd, "bvh_morton");
      passes.morton.record(cmd, {&arrays, &texels, info, keys, values, n});
    }
    passes.sort.record(cmd,
                       {keys, values, keysTmp, valuesTmp, hist, partials, n, sc.keyTexels.handle(),
                        sc.valueTexels.handle(), sc.keyTmpTexels.handle(), sc.valueTmpTexels.handle()},
                       &timer);
    if (usePloc) {
      const PlocPass::Args a = plocArgs();  // makes the pass on first need: before passes.ploc is read
      passes.ploc->record(cmd, a, plocIterations, &timer);
      // One treelet round over the upper tree, where PLOC's greedy merges are weakest.
      if (plocTreelets)
        passes.treelet.record(cmd, treeletArgs(options.plocTreeletMinTriangles), &timer);
    } else {
      {
        vk::TimedScope scope(&timer, cmd, "bvh_lbvh");
        passes.lbvh.record(cmd, {&arrays, &texels, keys, values, sc.keyTexels.handle(), n});
      }
      if (n > 1) {
        vk::TimedScope scope(&timer, cmd, "bvh_refit");
        passes.refit.record(cmd, {&arrays, &texels, &counters, n});
      }
      for (uint32_t round = 0; round < treeletRounds && n > 2; ++round) {
        // Karras & Aila grow the smallest restructured subtree each round: the bottom levels
        // improve most in the first round, later rounds polish the upper tree at less cost.
        passes.treelet.record(cmd, treeletArgs(options.treeletMinTriangles << round), &timer);
      }
    }
    if (n > 1 && !usePloc) {
      vk::TimedScope scope(&timer, cmd, "bvh_subtree_count");
      passes.subtreeCount.record(cmd, {&arrays, &texels, counters, subtreeNodes, n});
    }
    EmitPass::Args emit{&arrays, &texels, info, counters, sc.slotTexels.handle()};
    emit.subtreeNodes = subtreeNodes;
    emit.positions = positions;
    emit.levelNodes = nodeList;
    emit.leafBases = vk::BufferRange(keys, 0, 4ull * interiorCount);
    emit.schedule = &schedule;
    emit.triangleCount = n;
    emit.exactNodes = bvh.hasExactNodes;
    emit.quantizedNodes = bvh.hasQuantizedNodes;
    passes.emit.record(cmd, emit, &timer);
  };

  uint32_t rounds = treeletRoundsFor(options, n);
  // PLOC iterations recorded: those past the last merge still cost their dispatches. Spheres of
  // 100K, 250K, 500K and 1.05M triangles needed 59, 64, 71 and 82-85, the test meshes of 2,000 at
  // most 32; a tree left unfinished is rebuilt with twice as many (every iteration merges, so
  // n - 1 always suffice).
  // With the tail, the global iterations need only reach plocTailClusters (then they dispatch
  // nothing) or at most kPlocTailCapacity: on the 1M-triangle bench mesh each left about 0.76 of
  // the clusters from the eighth on (count 77K after 8, 4949 after 18, 2973 after 20), so
  // 4 ln(n / tailClusters) + 2 leaves room for meshes that merge more slowly.
  uint32_t log2n = 0;
  while ((uint64_t(1) << log2n) < n) ++log2n;
  uint32_t plocIterations = std::min<uint32_t>(16 + 4 * log2n, n);
  if (plocTailClusters != 0)
    plocIterations = std::min<uint32_t>(
        2 + uint32_t(std::ceil(4.0 * std::log(std::max(1.0, double(n) / plocTailClusters)))), n);
  bb::BvhBuildNode root{};
  bb::BvhBuildInfo done{};
  bb::PlocState plocState{};
  for (;;) {
    ctx.submitAndWait([&](VkCommandBuffer cmd) { record(cmd, rounds, plocIterations); });
    if (usePloc) {
      plocState = plocScratch_->state.downloadVector<bb::PlocState>(1)[0];
      const uint32_t left = plocState.count[PlocPass::finalParity(plocLocalRounds, plocIterations)];
      if (left != 1) {
        if (plocIterations >= n)
          throw DeviceError("bvh: PLOC left " + std::to_string(left) + " clusters after " +
                            std::to_string(plocIterations) + " iterations");
        plocIterations = std::min(2 * plocIterations, n);
        continue;
      }
    }
    root = n > 1 ? interior.downloadVector<bb::BvhBuildNode>(1)[0] : leaves.downloadVector<bb::BvhBuildNode>(1)[0];
    done = info.downloadVector<bb::BvhBuildInfo>(1)[0];
    uint32_t height = n > 1 ? (root.flags >> bb::kTraversalHeightShift) & bb::kHeightMask : 1;
    // The LBVH alone has at most 30 + ceil(log2 N) + 1 <= 58 levels (N <= 2^27, the leaf
    // index field); restructuring or PLOC can deepen it, so a tree past the traversal bound is
    // rebuilt as a plain LBVH.
    if (height <= gpu::bvh::kBvhMaxDepth || (rounds == 0 && !usePloc)) {
      if (height > gpu::bvh::kBvhMaxDepth)
        throw DeviceError("bvh: tree depth " + std::to_string(height) + " exceeds kBvhMaxDepth");
      if (stats) {
        stats->depth = height;
        stats->treeletRounds = usePloc ? (plocTreelets ? 1 : 0) : rounds;
        stats->plocIterations = usePloc ? plocState.iterations : 0;
        stats->plocLocalRounds = usePloc ? plocLocalRounds : 0;
        stats->plocTailClusters = usePloc ? plocTailClusters : 0;
      }
      break;
    }
    rounds = 0;
    usePloc = false;
  }
  if (done.leafCounter != n)
    throw DeviceError("bvh: GPU build placed " + std::to_string(done.leafCounter) + " of " +
                      std::to_string(n) + " triangles");
  if (stats) {
    std::vector<vk::PassTime> perScope = timer.results();
    stats->passes.clear();
    stats->totalMs = 0;
    for (const auto& p : perScope) {
      auto it = std::find_if(stats->passes.begin(), stats->passes.end(),
                             [&](const vk::PassTime& q) { return q.name == p.name; });
      if (it == stats->passes.end())
        stats->passes.push_back(p);
      else
        it->ms += p.ms;
      stats->totalMs += p.ms;
    }
    glm::vec3 d = root.hi - root.lo;
    double area = 2.0 * (double(d.x) * d.y + double(d.y) * d.z + double(d.z) * d.x);
    // One triangle: the root node over a single leaf (root.cost is that leaf's).
    double cost = n > 1 ? root.cost : gpu::bvh::kSahNodeCost * area + root.cost;
    stats->sahCost = area > 0 ? cost / area : 0.0;
    stats->scratchBytes = scratchBytes + (usePloc ? plocScratch_->bytes : 0);
  }
  return bvh;
}

}  // namespace osr::bvh
