// The GPU BVH build (src/bvh/gpu_builder.cpp): intermediate structures, bindings and push
// constants of its passes, and the integer helpers both C++ (tests, CPU twins) and GLSL use.
//
// Passes, in order (one .comp each):
//   bvh_bounds        per-triangle vertex copy + scene centroid bounds (subgroup + atomic min/max)
//   bvh_morton        30-bit Morton code of each centroid in the centroid bounds
//   bvh_radix_histogram / bvh_scan_reduce / bvh_scan_top / bvh_scan_apply / bvh_radix_scatter
//                     stable LSD radix sort of (code, triangle), 8 bits per round
//   bvh_lbvh          hierarchy from the sorted codes (Karras 2012); bvh_ploc_* instead for
//                     large scenes (see PLOC below), which also do the refit's work
//   bvh_refit         bounds, triangle counts, SAH costs and heights bottom-up (atomic counters)
//   bvh_treelet_*     treelet restructuring (Karras & Aila 2013), level by level, several rounds
//   bvh_subtree_count traversal nodes per subtree (atomic counters)
//   bvh_emit_nodes    the nodes of the traversal layout of shared/bvh.h (subtrees collapsed into
//                     leaves, exact and quantized), depth by depth in depth-first order, and
//                     where each leaf's triangles go
//   bvh_emit_leaves   the leaf triangles, in place
// Build nodes share one index space: interior nodes [0, N-1) (root 0), leaves [N-1, 2N-1) in
// sorted order, in two arrays.
//
// Scale: the arrays that hold tens of bytes per triangle (scene triangles and vertices, prims,
// build nodes, the traversal layout: BuildArrays) are storage bindings while each fits one
// (maxStorageBufferRange: 128 MiB on lavapipe, i.e. 2.1M traversal nodes); past that the build
// runs pipelines specialised (kBuildSpecByAddress) to reach them through buffer device
// addresses (GL_EXT_buffer_reference), so one may span a whole allocation
// (maxMemoryAllocationSize: 2 GiB on lavapipe). lib/bvh_build_arrays.glsl has the accessors.
// The 4-byte-per-triangle arrays (keys, values, counters, node lists) stay storage bindings:
// at 128 MiB they hold 32M.
#ifndef OSR_SHARED_BVH_BUILD_H
#define OSR_SHARED_BVH_BUILD_H
#include "shared/types.h"
#include "shared/bvh.h"

#ifdef __cplusplus
#define OSR_BVH_FN inline
#else
#define OSR_BVH_FN
#endif

OSR_NAMESPACE_BEGIN(bvh_build)
OSR_CONST(uint, kWorkgroupSize, 64u);
// Per-item passes dispatch a grid of at most kMaxGroupsX groups in x (the least that Vulkan
// guarantees for maxComputeWorkGroupCount[0]; 64 x 65535 = 4.2M invocations) and as many rows
// in y as needed; bvhBuildItem() flattens it.
OSR_CONST(uint, kMaxGroupsX, 65535u);
OSR_CONST(uint, kInvalidNode, 0xffffffffu);
// BvhBuildNode.flags: whether the subtree becomes one leaf; its height (interior levels down to
// the deepest leaf, 0 for a leaf), which orders the treelet schedule; and its height as
// traversal counts it (0 for a leaf or a collapsed subtree), which bounds the stack.
OSR_CONST(uint, kFlagCollapsed, 0x80000000u);
OSR_CONST(uint, kHeightMask, 0x7fffu);
OSR_CONST(uint, kTraversalHeightShift, 16u);

struct BvhBuildNode {
  vec3 lo;
  float cost;          // SAH cost of the subtree (not normalised): see shared/bvh.h
  vec3 hi;
  uint triangleCount;  // triangles below
  uint left;           // interior: child indices; leaf: left = scene triangle index
  uint right;
  uint parent;         // kInvalidNode at the root
  uint flags;
};

struct BvhBuildInfo {
  uvec4 centroidMin;  // ordered-uint encoded floats (bvhOrderedFromBits), xyz
  uvec4 centroidMax;
  uint leafCounter;   // leaf entries allocated so far (bvh_emit_nodes)
  uint _pad0;
  uint _pad1;
  uint _pad2;
};

// Binding slots of the large arrays in every pass that includes lib/bvh_build_arrays.glsl; its
// own bindings follow from kBuildArrayBindingCount.
OSR_CONST(uint, kBuildBindingTriangles, 0u);
OSR_CONST(uint, kBuildBindingVertices, 1u);
OSR_CONST(uint, kBuildBindingPrims, 2u);
OSR_CONST(uint, kBuildBindingInterior, 3u);
OSR_CONST(uint, kBuildBindingLeaves, 4u);
OSR_CONST(uint, kBuildBindingNodes, 5u);
OSR_CONST(uint, kBuildBindingLeafTriangles, 6u);
OSR_CONST(uint, kBuildBindingTraversalNodes, 7u);
OSR_CONST(uint, kBuildArrayBindingCount, 8u);
OSR_CONST(uint, kBuildSpecByAddress, 2u);  // spec constant id: bool, read the arrays by address

// Device addresses (low word, high word: GL_EXT_buffer_reference_uvec2) of the large arrays
// when kBuildSpecByAddress is set; 0 where a pass does not use one.
struct BuildArrays {
  uvec2 triangles;      // scene Triangle[triangleCount]
  uvec2 vertices;       // scene Vertex[]
  uvec2 prims;          // BvhLeafTriangle[triangleCount]: vertex copies in scene order
  uvec2 interior;       // BvhBuildNode[triangleCount - 1]
  uvec2 leaves;         // BvhBuildNode[triangleCount], sorted order
  uvec2 nodes;          // out of bvh_emit_nodes: BvhNode[triangleCount - 1] (or 1, unwritten)
  uvec2 leafTriangles;  // out of bvh_emit_leaves: BvhLeafTriangle[triangleCount]
  uvec2 traversalNodes; // out of bvh_emit_nodes: BvhTraversalNode[triangleCount - 1] (or 1,
                        // unwritten)
};

// Generic push block of the build passes.
struct BuildPush {
  uint triangleCount;
  uint param;   // pass-specific: see each binding list
  uint param2;
  uint _pad0;
  BuildArrays arrays;
};

// Texel reads of the build arrays (lib/bvh_build_texels.glsl): passes whose reads of interior,
// leaves and prims are scattered, and never of data written in the same dispatch, declare
// RGBA32UI views of them at kBuildTexelBindingCount slots from their own base slot. Where spec
// constant kBuildSpecTexels is set they read through the views (on lavapipe a texel fetch is a
// gather, a storage load a loop over the SIMD lanes), else through the arrays.
OSR_CONST(uint, kBuildTexelInterior, 0u);  // slot offsets from the pass's base slot
OSR_CONST(uint, kBuildTexelLeaves, 1u);
OSR_CONST(uint, kBuildTexelPrims, 2u);
OSR_CONST(uint, kBuildTexelBindingCount, 3u);
OSR_CONST(uint, kBuildSpecTexels, 4u);  // spec constant id: bool
OSR_CONST(uint, kBuildNodeTexels, 3u);  // 16-byte texels per BvhBuildNode

// bvh_bounds: arrays triangles, vertices (in), prims (out).
OSR_CONST(uint, kBoundsBindingInfo, kBuildArrayBindingCount);
// RGBA32UI views of the scene's triangles and vertices (a Triangle is one texel, a Vertex two),
// read where spec constant kBoundsSpecSceneTexels is set: on lavapipe four gathers per
// triangle, where the storage loads are twelve loops over the lanes (a specialization, not a
// push constant: on lavapipe the path not taken would cost its loads too).
OSR_CONST(uint, kBoundsBindingTriangleTexels, kBuildArrayBindingCount + 1u);
OSR_CONST(uint, kBoundsBindingVertexTexels, kBuildArrayBindingCount + 2u);
OSR_CONST(uint, kBoundsBindingCount, kBuildArrayBindingCount + 3u);
OSR_CONST(uint, kBoundsSpecSceneTexels, 9u);  // spec constant id: bool

// bvh_morton: arrays prims (through texels).
OSR_CONST(uint, kMortonBindingInfo, kBuildArrayBindingCount);
OSR_CONST(uint, kMortonBindingKeys, kBuildArrayBindingCount + 1u);
OSR_CONST(uint, kMortonBindingValues, kBuildArrayBindingCount + 2u);
OSR_CONST(uint, kMortonBindingTexels, kBuildArrayBindingCount + 3u);
OSR_CONST(uint, kMortonBindingCount, kMortonBindingTexels + kBuildTexelBindingCount);

// Radix sort: each invocation owns a chunk of kRadixChunk consecutive keys and keeps its 256
// digit counters in registers/private memory: no shared memory and no barriers, which lavapipe
// runs fastest, and no assumption on the subgroup size. The histogram is digit-major
// (hist[digit * chunkCount + chunk]) so that one exclusive scan yields every chunk's output
// offset per digit, which keeps the scatter stable. param = bit shift, param2 = chunkCount.
OSR_CONST(uint, kRadixBits, 8u);
OSR_CONST(uint, kRadixBins, 256u);
OSR_CONST(uint, kRadixChunk, 512u);
OSR_CONST(uint, kRadixKeyBits, 30u);
// Each invocation reads its own chunk, so the lanes' reads are scattered: where spec constant
// kRadixSpecTexels is set they come from R32UI views of the input keys and values (on lavapipe a
// gather, where a storage load is a loop over the lanes), else from the storage bindings. Both
// passes share one binding list.
OSR_CONST(uint, kRadixBindingKeysIn, 0u);
OSR_CONST(uint, kRadixBindingValuesIn, 1u);
OSR_CONST(uint, kRadixBindingHist, 2u);
OSR_CONST(uint, kRadixBindingKeysOut, 3u);
OSR_CONST(uint, kRadixBindingValuesOut, 4u);
OSR_CONST(uint, kRadixBindingKeyTexelsIn, 5u);
OSR_CONST(uint, kRadixBindingValueTexelsIn, 6u);
OSR_CONST(uint, kRadixBindingCount, 7u);
OSR_CONST(uint, kRadixSpecTexels, 6u);  // spec constant id: bool

// Exclusive scan in three dispatches: per-segment sums, a serial scan of the sums by one
// invocation, per-segment scans. triangleCount = element count, param = segment count.
OSR_CONST(uint, kScanSegment, 1024u);
OSR_CONST(uint, kScanBindingData, 0u);
OSR_CONST(uint, kScanBindingPartials, 1u);
OSR_CONST(uint, kScanBindingCount, 2u);

// bvh_lbvh: arrays prims (in), interior, leaves (out). The binary searches of its delta() read
// the sorted keys at scattered indices; where spec constant kLbvhSpecKeyTexels is set they come
// from an R32UI texel view of the keys (on lavapipe a texel fetch is a gather, a storage load a
// loop over the SIMD lanes), else from the storage binding.
OSR_CONST(uint, kLbvhBindingKeys, kBuildArrayBindingCount);
OSR_CONST(uint, kLbvhBindingValues, kBuildArrayBindingCount + 1u);
OSR_CONST(uint, kLbvhBindingKeyTexels, kBuildArrayBindingCount + 2u);
OSR_CONST(uint, kLbvhBindingTexels, kBuildArrayBindingCount + 3u);  // texel reads (of prims)
OSR_CONST(uint, kLbvhBindingCount, kLbvhBindingTexels + kBuildTexelBindingCount);
OSR_CONST(uint, kLbvhSpecKeyTexels, 3u);  // spec constant id: bool

// bvh_refit (climb) and the treelet passes: arrays interior, leaves.
OSR_CONST(uint, kClimbBindingCounters, kBuildArrayBindingCount);
OSR_CONST(uint, kClimbBindingCount, kBuildArrayBindingCount + 1u);
OSR_CONST(uint, kClimbSpecFences, 1u);  // spec constant id: bool, memory fences around the counter
// bvh_refit reads what bvh_lbvh wrote (leaves, every node's links) through texels.
OSR_CONST(uint, kRefitBindingTexels, kClimbBindingCount);
OSR_CONST(uint, kRefitBindingCount, kRefitBindingTexels + kBuildTexelBindingCount);

// Treelet restructuring (Karras & Aila 2013) runs level-synchronously: the nodes to restructure
// (interior, not collapsed, at least `minTriangles` below) are bucketed by height, then one
// indirect dispatch per height processes a bucket with every SIMD lane busy. Nodes of one
// height are disjoint subtrees, and everything below a node has a smaller height, so a node is
// restructured after all of its descendants without any invocation waiting for another.
//   bvh_treelet_count   banks[b][h].count per bank and height   (param = minTriangles)
//   bvh_treelet_plan    levels[h] (count, offset), bank cursors, indirect dispatch arguments
//                       per height (1 invocation)
//   bvh_treelet_scatter node lists per height                   (param = minTriangles)
//   bvh_treelet         restructures the nodes of one height (param = height)
// Counting and appending go to one of kTreeletBanks copies of the per-height counters, picked
// by workgroup: with one copy, lavapipe's two threads took its cache line from each other for
// every atomic, which was most of the counting and appending passes' time.
OSR_CONST(uint, kTreeletMaxLeaves, 7u);   // 2^7 subsets per dynamic program
OSR_CONST(uint, kTreeletSpecLeaves, 0u);  // spec constant id: leaves per treelet (3..7)
// Heights scheduled; a taller tree exceeds kBvhMaxDepth anyway and is rebuilt without treelets.
OSR_CONST(uint, kTreeletMaxLevels, 128u);
OSR_CONST(uint, kTreeletBanks, 16u);
// LevelList[kTreeletMaxLevels], DispatchArgs[kTreeletMaxLevels], then per bank b and height
// h at [b * kTreeletMaxLevels + h] a uvec2: the count, and the cursor (next free list entry).
OSR_CONST(uint, kTreeletBindingSchedule, kBuildArrayBindingCount + 1u);
OSR_CONST(uint, kTreeletBindingNodeList, kBuildArrayBindingCount + 2u);  // uint per interior node
// Subtree node counts (bvh_subtree_count's; then its R32UI view), kept up to date where param2 has
// kTreeletCountNodes (after PLOC, whose merges counted them).
OSR_CONST(uint, kTreeletBindingSubtreeNodes, kBuildArrayBindingCount + 3u);
OSR_CONST(uint, kTreeletBindingTexels, kBuildArrayBindingCount + 5u);  // bvh_treelet's texel reads
OSR_CONST(uint, kTreeletCountNodes, 1u);
OSR_CONST(uint, kTreeletBindingCount, kTreeletBindingTexels + kBuildTexelBindingCount);
// One level (height or depth) of a level-synchronous pass: its nodes in the node list.
struct LevelList {
  uint count;   // nodes of this level
  uint offset;  // where they start in the node list
  uint _pad0;
  uint _pad1;
};
struct DispatchArgs {
  uint x;
  uint y;
  uint z;
};

// bvh_subtree_count: traversal nodes per subtree (0 for a leaf or a collapsed subtree),
// bottom-up like bvh_refit; arrays interior, leaves (through texels), climb counters zeroed.
OSR_CONST(uint, kSubtreeCountBindingNodes, kClimbBindingCount);  // uint per interior node (out)
OSR_CONST(uint, kSubtreeCountBindingTexels, kClimbBindingCount + 1u);
OSR_CONST(uint, kSubtreeCountBindingCount, kSubtreeCountBindingTexels + kBuildTexelBindingCount);

// PLOC (Meister and Bittner 2018, "Parallel Locally-Ordered Clustering for Bounding Volume
// Hierarchy Construction"): the builder for large scenes, in place of bvh_lbvh + bvh_refit + a
// full treelet round (src/bvh/gpu_builder.h, Hierarchy). Clusters start as the sorted
// triangles; each iteration every cluster finds the cluster within kPlocRadius places (in
// Morton order) whose union with it has the least surface area, mutual nearest pairs merge into
// a new interior node, and the survivors are compacted in order. A merge knows both children,
// so it writes the node's bounds, SAH cost, collapse decision, heights and traversal-node count
// at once, with no bottom-up climb. (The builder then runs one treelet round over the upper tree,
// which keeps the counts, so no bvh_subtree_count.)
//   bvh_ploc_init     leaves (as bvh_lbvh's) and the first clusters
//   bvh_ploc_local    optional (GpuBuildOptions::plocLocalRounds, off by default): merges
//                     within chunks of 8 clusters in registers, halving them, before the
//                     iterations below
//   bvh_ploc_nearest  each cluster's nearest neighbour (one strict order of pairs, so a mutual
//                     pair always exists and every iteration merges)
//   bvh_ploc_count    per-subgroup counts of the clusters that survive the merge, and of the
//                     mutual pairs
//   bvh_ploc_plan     one workgroup: scans both counts; the next iteration's cluster count,
//                     this one's pair count, and indirect dispatch arguments
//   bvh_ploc_compact  survivors (a pair's lower cluster now holding the pair's parent) to the
//                     other cluster array, in order; the pairs to the pair list
//   bvh_ploc_merge    one invocation per pair (every lane busy: a quarter of the clusters
//                     merge in an iteration): the interior node, its children's parent and
//                     its subtree's traversal nodes
//   bvh_ploc_tail     GpuBuildOptions::plocTailClusters (default 1024): one workgroup runs the
//                     iterations from PlocState.tailClusters clusters down to the root, in one
//                     dispatch (below that count the global iterations are dispatches with
//                     little work each, most of them on large meshes)
//   bvh_ploc_root     once, after the iterations: the root swaps places with the node at 0
// Iterations alternate two cluster arrays and two halves of PlocState (param = parity); an
// iteration whose count is 1 dispatches no group, so the host records a number of them chosen
// ahead (PlocPass::Iterations) and records again with more if the tree is not complete.
// A cluster is its box, its build node and its first leaf (the lowest sorted index of its
// leaves), in two texels. The nearest-neighbour search reads clusters in Morton order, a
// neighbour's two texels each; compaction moves them; a merge reads its children's other fields
// from the build nodes. Boxes quantized to 16 or 21 bits per plane (one texel with the node
// elsewhere) built a little faster but gave trees that traced slower (docs/bvh.md).
// Interior indices as Karras's LBVH numbers them, so that a node lies near its leaves: a node
// takes the first leaf of whichever child has the later one, minus 1. Every leaf but leaf 0 is
// that for exactly one node (follow the subtrees whose first leaf it is up to the largest: that
// subtree's parent), so the indices are 0 to N-2, each once, and depend only on the tree. The
// root then swaps places with the node at 0, where the emit passes and the host expect it.
// The search radius: 3 builds as good a tree as 4 in less time, and smaller radii, even for
// the first iterations only, give trees that trace slower (osr-bench bvh and trace;
// docs/bvh.md, bench/results/bvh.jsonl and trace.jsonl).
OSR_CONST(uint, kPlocRadius, 3u);
OSR_CONST(uint, kPlocBindingClusterTexels, kBuildArrayBindingCount);       // this iteration's
                                                                            // clusters (RGBA32UI)
OSR_CONST(uint, kPlocBindingNextClusters, kBuildArrayBindingCount + 1u);    // compaction target
OSR_CONST(uint, kPlocBindingNearest, kBuildArrayBindingCount + 2u);         // uint per cluster
OSR_CONST(uint, kPlocBindingNearestTexels, kBuildArrayBindingCount + 3u);   // R32UI view of it
OSR_CONST(uint, kPlocBindingPartials, kBuildArrayBindingCount + 4u);        // uint per subgroup
OSR_CONST(uint, kPlocBindingState, kBuildArrayBindingCount + 5u);           // PlocState
OSR_CONST(uint, kPlocBindingValues, kBuildArrayBindingCount + 6u);          // sorted triangles
OSR_CONST(uint, kPlocBindingPairs, kBuildArrayBindingCount + 7u);           // uvec4 per pair
OSR_CONST(uint, kPlocBindingSubtreeNodes, kBuildArrayBindingCount + 8u);    // uint per interior
                                                                            // node, then its view
OSR_CONST(uint, kPlocBindingTexels, kBuildArrayBindingCount + 10u);         // build texels
// bvh_ploc_tail: its two cluster arrays (uvec4 pairs, param2 clusters each), and the cluster
// array of parity 1's view (parity 0's at kPlocBindingClusterTexels): where the tail starts.
OSR_CONST(uint, kPlocBindingTailClusters, kPlocBindingTexels + kBuildTexelBindingCount);
OSR_CONST(uint, kPlocBindingClusterTexels1, kPlocBindingTailClusters + 1u);
OSR_CONST(uint, kPlocBindingCount, kPlocBindingClusterTexels1 + 1u);
// The most clusters bvh_ploc_tail takes (its scratch: 64 bytes each). A one-workgroup loop runs
// at most count - 1 iterations (each merges a pair), within llvmpipe's 65535 per loop.
OSR_CONST(uint, kPlocTailCapacity, 16384u);
// bvh_ploc_local (before the global iterations, rounds chosen by the builder): PLOC within
// chunks of kPlocLocalChunk clusters in Morton order, in registers, down to plocLocalKeep of a
// chunk's m clusters (half, rounded up; one or two keep theirs, so two clusters are left for
// the global iterations' root at least); plocLocalCount(count) clusters are left in all.
OSR_CONST(uint, kPlocLocalChunk, 8u);
OSR_BVH_FN uint plocLocalKeep(uint m) { return m <= 2u ? m : (m + 1u) / 2u; }
OSR_BVH_FN uint plocLocalCount(uint count) {
  return count / kPlocLocalChunk * (kPlocLocalChunk / 2u) + plocLocalKeep(count % kPlocLocalChunk);
}
// Partials (uint each): per subgroup of an iteration's dispatch, its surviving clusters from 0,
// its pairs from triangleCount + kWorkgroupSize (a dispatch has at most that many subgroups).
struct PlocState {
  uvec2 count;       // clusters at the start of an iteration of parity 0 / 1
  uint iterations;   // iterations that had more than one cluster
  uint pairs;        // mutual pairs of the current iteration (bvh_ploc_plan)
  DispatchArgs args0;    // per-cluster dispatch of an iteration of parity 0, then of parity 1
  DispatchArgs args1;    // (adjacent: the host offsets by parity)
  DispatchArgs pairArgs; // per-pair dispatch of the current iteration
  uint root;             // where the last merge made the root (bvh_ploc_root moves it to 0)
  uint clusterParity;    // which cluster array holds the clusters (the last pass that merged)
  uint tailClusters;     // iterations at or below this many clusters are left to bvh_ploc_tail
};

// bvh_emit_nodes: arrays interior, leaves (texels), nodes, traversalNodes (out); info, slots,
// positions (out), subtree node counts, the depth schedule and node lists. It runs once per
// depth (param) with an indirect dispatch that the depth before sized, so the traversal nodes
// come out in depth-first order: a walk that descends to child a finds it next to its parent,
// and every subtree is one contiguous run.
// The schedule: LevelList[kEmitMaxLevels], then DispatchArgs[kEmitMaxLevels]; the host sets
// depth 0 (the root) and y = z = 1 everywhere. positions[i]: interior build node i's traversal
// index; leafBases[i]: the first leaf entry of its subtree, so that leaf entries too come in
// depth-first order. Both are written for the nodes that become traversal nodes (the host sets
// the root's: 0 and 0).
// bvh_emit_leaves: arrays interior, leaves, prims (texels), leafTriangles (out); slots (through
// the R32UI view where spec constant kEmitSpecSlotTexels is set, else the storage binding).
// slots[i] (uint per interior node) tells where the triangles of interior node i's leaf-like
// children go: bvhEmitSlot(first leaf entry of a's, entries of a's (0 when a is a node)); b's
// follow a's. Nodes that do not become traversal nodes leave theirs unset; no leaf reads it.
#ifdef __cplusplus
OSR_CONST(uint, kEmitMaxLevels, bvh::kBvhMaxDepth + 1u);
#else
OSR_CONST(uint, kEmitMaxLevels, kBvhMaxDepth + 1u);
#endif
OSR_CONST(uint, kEmitBindingInfo, kBuildArrayBindingCount);
OSR_CONST(uint, kEmitBindingSlots, kBuildArrayBindingCount + 1u);
OSR_CONST(uint, kEmitBindingSlotTexels, kBuildArrayBindingCount + 2u);
OSR_CONST(uint, kEmitBindingTexels, kBuildArrayBindingCount + 3u);
OSR_CONST(uint, kEmitBindingPositions, kEmitBindingTexels + kBuildTexelBindingCount);  // uint per interior node
OSR_CONST(uint, kEmitBindingSubtreeNodes, kEmitBindingPositions + 1u);  // bvh_subtree_count's
OSR_CONST(uint, kEmitBindingSchedule, kEmitBindingPositions + 2u);
OSR_CONST(uint, kEmitBindingLevelNodes, kEmitBindingPositions + 3u);  // uint per interior node
OSR_CONST(uint, kEmitBindingLeafBases, kEmitBindingPositions + 4u);  // uint per interior node
OSR_CONST(uint, kEmitBindingCount, kEmitBindingPositions + 5u);
OSR_CONST(uint, kEmitSpecSlotTexels, 5u);  // spec constant id: bool
// bvh_emit_nodes' specialization (not push constants: on lavapipe a branch costs every lane
// whether taken or not, and the unwritten form's stores or the one-triangle root's quantization
// cost every subgroup). kEmitSpecForms: which node arrays to write (bvh::NodeForms,
// src/bvh/gpu_builder.h), kEmitExactNodes | kEmitQuantizedNodes; kEmitSpecSingleTriangle: the
// build has one triangle (the root alone, over one leaf).
OSR_CONST(uint, kEmitSpecForms, 7u);           // spec constant id: uint
OSR_CONST(uint, kEmitSpecSingleTriangle, 8u);  // spec constant id: bool
OSR_CONST(uint, kEmitExactNodes, 1u);
OSR_CONST(uint, kEmitQuantizedNodes, 2u);
OSR_CONST(uint, kEmitSlotCountShift, 27u);  // above kBvhLeafFirstMask: first entries < 2^27
OSR_BVH_FN uint bvhEmitSlot(uint first, uint countA) { return first | (countA << kEmitSlotCountShift); }

// A float's bits mapped to a uint that orders like the float (atomicMin/Max on floats).
OSR_BVH_FN uint bvhOrderedFromBits(uint bits) {
  return (bits & 0x80000000u) != 0u ? ~bits : (bits | 0x80000000u);
}
OSR_BVH_FN uint bvhBitsFromOrdered(uint o) {
  return (o & 0x80000000u) != 0u ? (o & 0x7fffffffu) : ~o;
}

// Spreads the low 10 bits of v to every third bit.
OSR_BVH_FN uint bvhExpandBits(uint v) {
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}
// 30-bit Morton code of a point given in units of the centroid bounds ([0,1]^3, clamped).
OSR_BVH_FN uint bvhMorton(float x, float y, float z) {
  x = x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f;  // also maps NaN to 0
  y = y > 0.0f ? (y < 1.0f ? y : 1.0f) : 0.0f;
  z = z > 0.0f ? (z < 1.0f ? z : 1.0f) : 0.0f;
  uint qx = uint(x * 1023.0f);
  uint qy = uint(y * 1023.0f);
  uint qz = uint(z * 1023.0f);
  return bvhExpandBits(qx) * 4u + bvhExpandBits(qy) * 2u + bvhExpandBits(qz);
}

#ifndef __cplusplus
// The item (triangle, node) of this invocation in a grid of kMaxGroupsX-wide rows.
uint bvhBuildItem() {
  return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * kWorkgroupSize);
}
#endif

OSR_NAMESPACE_END
#endif
