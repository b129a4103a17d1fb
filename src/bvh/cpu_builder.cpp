#include "bvh/cpu_builder.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>

#include "bvh/aabb.h"
#include "bvh/node_quantize.h"
#include "common/error.h"

namespace osr::bvh {

namespace {

using gpu::bvh::BvhNode;
using gpu::bvh::kBvhEmptyChild;
using gpu::bvh::kBvhLeafCountShift;
using gpu::bvh::kBvhLeafFlag;
using gpu::bvh::kBvhMaxDepth;
using gpu::bvh::kSahNodeCost;
using gpu::bvh::kSahTriangleCost;

// An inverted box far from any scene: no ray enters it (empty child of a one-triangle tree).
constexpr float kFar = 1e30f;

class Builder {
 public:
  Builder(std::span<const gpu::scene::Vertex> vertices,
          std::span<const gpu::scene::Triangle> triangles, const CpuBuildOptions& options)
      : options_(options) {
    size_t n = triangles.size();
    boxes_.resize(n);
    centroids_.resize(n);
    order_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const auto& t = triangles[i];
      Aabb b;
      b.grow(vertices[t.v0].position);
      b.grow(vertices[t.v1].position);
      b.grow(vertices[t.v2].position);
      boxes_[i] = b;
      centroids_[i] = 0.5f * (b.lo + b.hi);
      order_[i] = static_cast<uint32_t>(i);
    }
  }

  HostBvh build() {
    uint32_t n = static_cast<uint32_t>(order_.size());
    out_.nodes.reserve(n);
    out_.leafTriangles.reserve(n);
    Aabb bounds = rangeBounds(0, n);
    if (n == 1) {
      BvhNode root{};
      setChild(root, 0, makeLeaf(0, 1), bounds);
      root.b = kBvhEmptyChild;
      root.bMin = glm::vec3(kFar);
      root.bMax = glm::vec3(-kFar);
      out_.nodes.push_back(root);
    } else {
      uint32_t mid = split(0, n, 1, bounds, /*allowLeaf=*/false);
      buildNode(0, mid, n, 1);
    }
    return std::move(out_);
  }

 private:
  Aabb rangeBounds(uint32_t begin, uint32_t end) const {
    Aabb b;
    for (uint32_t i = begin; i < end; ++i) b.grow(boxes_[order_[i]]);
    return b;
  }

  static void setChild(BvhNode& node, int side, uint32_t ref, const Aabb& b) {
    if (side == 0) {
      node.a = ref;
      node.aMin = b.lo;
      node.aMax = b.hi;
    } else {
      node.b = ref;
      node.bMin = b.lo;
      node.bMax = b.hi;
    }
  }

  uint32_t makeLeaf(uint32_t begin, uint32_t end) {
    uint32_t first = static_cast<uint32_t>(out_.leafTriangles.size());
    for (uint32_t i = begin; i < end; ++i) out_.leafTriangles.push_back(order_[i]);
    return kBvhLeafFlag | ((end - begin) << kBvhLeafCountShift) | first;
  }

  // Interior node at `depth` (root = 1) over [begin, end), split at mid.
  uint32_t buildNode(uint32_t begin, uint32_t mid, uint32_t end, uint32_t depth) {
    uint32_t index = static_cast<uint32_t>(out_.nodes.size());
    out_.nodes.emplace_back();
    uint32_t ranges[3] = {begin, mid, end};
    for (int side = 0; side < 2; ++side) {
      uint32_t b = ranges[side], e = ranges[side + 1];
      Aabb box = rangeBounds(b, e);
      uint32_t ref;
      uint32_t childMid = e - b == 1 ? b : split(b, e, depth + 1, box, /*allowLeaf=*/true);
      if (childMid == b)
        ref = makeLeaf(b, e);
      else
        ref = buildNode(b, childMid, e, depth + 1);
      setChild(out_.nodes[index], side, ref, box);
    }
    return index;
  }

  // Median split on the widest centroid axis (or by position when all centroids coincide).
  uint32_t medianSplit(uint32_t begin, uint32_t end, const Aabb& cb) {
    glm::vec3 d = cb.hi - cb.lo;
    int axis = d.x >= d.y && d.x >= d.z ? 0 : (d.y >= d.z ? 1 : 2);
    uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](uint32_t x, uint32_t y) { return centroids_[x][axis] < centroids_[y][axis]; });
    return mid;
  }

  // Returns the split position in (begin, end), or begin when a leaf is cheaper (allowLeaf).
  // `depth` is the depth of the node that would hold the two halves.
  uint32_t split(uint32_t begin, uint32_t end, uint32_t depth, const Aabb& bounds, bool allowLeaf) {
    uint32_t n = end - begin;
    Aabb cb;
    for (uint32_t i = begin; i < end; ++i) cb.grow(centroids_[order_[i]]);
    // Median splits finish any range within ceil(log2 n) more levels; switch to them before the
    // SAH choice could push a path past kBvhMaxDepth.
    uint32_t medianLevels = std::bit_width(n - 1);
    if (depth + medianLevels + 1 >= kBvhMaxDepth) {
      if (allowLeaf && n <= options_.maxLeafTriangles) return begin;
      return medianSplit(begin, end, cb);
    }
    const uint32_t bins = options_.bins;
    float bestCost = std::numeric_limits<float>::infinity();
    int bestAxis = -1;
    uint32_t bestBin = 0;
    std::vector<Aabb> binBox(bins);
    std::vector<uint32_t> binCount(bins);
    std::vector<float> rightArea(bins);
    std::vector<uint32_t> rightCount(bins);
    for (int axis = 0; axis < 3; ++axis) {
      float extent = cb.hi[axis] - cb.lo[axis];
      if (!(extent > 0.0f)) continue;
      std::fill(binBox.begin(), binBox.end(), Aabb{});
      std::fill(binCount.begin(), binCount.end(), 0u);
      float scale = bins / extent;
      for (uint32_t i = begin; i < end; ++i) {
        uint32_t t = order_[i];
        uint32_t bin = binOf(centroids_[t][axis], cb.lo[axis], scale);
        binBox[bin].grow(boxes_[t]);
        binCount[bin]++;
      }
      Aabb acc;
      uint32_t count = 0;
      for (uint32_t b = bins - 1; b > 0; --b) {
        acc.grow(binBox[b]);
        count += binCount[b];
        rightArea[b] = acc.area();
        rightCount[b] = count;
      }
      acc = Aabb{};
      count = 0;
      for (uint32_t b = 1; b < bins; ++b) {  // plane between bin b-1 and b
        acc.grow(binBox[b - 1]);
        count += binCount[b - 1];
        if (count == 0 || rightCount[b] == 0) continue;
        float cost = acc.area() * count + rightArea[b] * rightCount[b];
        if (cost < bestCost) {
          bestCost = cost;
          bestAxis = axis;
          bestBin = b;
        }
      }
    }
    if (bestAxis < 0) {  // all centroids coincide
      if (allowLeaf && n <= options_.maxLeafTriangles) return begin;
      return begin + n / 2;
    }
    float area = bounds.area();
    float splitCost = kSahNodeCost * area + kSahTriangleCost * bestCost;
    float leafCost = kSahTriangleCost * area * n;
    if (allowLeaf && n <= options_.maxLeafTriangles && leafCost <= splitCost) return begin;
    float lo = cb.lo[bestAxis];
    float scale = bins / (cb.hi[bestAxis] - lo);
    auto it = std::partition(order_.begin() + begin, order_.begin() + end, [&](uint32_t t) {
      return binOf(centroids_[t][bestAxis], lo, scale) < bestBin;
    });
    uint32_t mid = static_cast<uint32_t>(it - order_.begin());
    if (mid == begin || mid == end) return medianSplit(begin, end, cb);  // rounding corner case
    return mid;
  }

  uint32_t binOf(float c, float lo, float scale) const {
    float f = (c - lo) * scale;
    uint32_t b = f > 0.0f ? static_cast<uint32_t>(f) : 0u;
    return std::min(b, options_.bins - 1);
  }

  CpuBuildOptions options_;
  std::vector<Aabb> boxes_;
  std::vector<glm::vec3> centroids_;
  std::vector<uint32_t> order_;
  HostBvh out_;
};

}  // namespace

HostBvh buildCpu(std::span<const gpu::scene::Vertex> vertices,
                 std::span<const gpu::scene::Triangle> triangles, const CpuBuildOptions& options) {
  if (triangles.empty()) throw InputError("bvh: a scene with no triangles has no BVH");
  if (options.maxLeafTriangles < 1 || options.maxLeafTriangles > gpu::bvh::kBvhMaxLeafTriangles ||
      options.bins < 2)
    throw InputError("bvh: CPU builder options out of range");
  for (size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    if (t.v0 >= vertices.size() || t.v1 >= vertices.size() || t.v2 >= vertices.size())
      throw InputError("bvh: triangle " + std::to_string(i) + " indexes past the " +
                       std::to_string(vertices.size()) + " vertices");
  }
  return Builder(vertices, triangles, options).build();
}

std::vector<gpu::bvh::BvhLeafTriangle> makeLeafTriangles(
    const HostBvh& tree, std::span<const gpu::scene::Vertex> vertices,
    std::span<const gpu::scene::Triangle> triangles) {
  std::vector<gpu::bvh::BvhLeafTriangle> out(tree.leafTriangles.size());
  for (size_t i = 0; i < out.size(); ++i) {
    uint32_t id = tree.leafTriangles[i];
    const auto& t = triangles[id];
    float idBits;
    std::memcpy(&idBits, &id, 4);
    out[i].v0 = glm::vec4(vertices[t.v0].position, idBits);
    out[i].v1 = glm::vec4(vertices[t.v1].position, 0.0f);
    out[i].v2 = glm::vec4(vertices[t.v2].position, 0.0f);
  }
  return out;
}

Bvh upload(const vk::Context& ctx, const HostBvh& tree,
           std::span<const gpu::scene::Vertex> vertices,
           std::span<const gpu::scene::Triangle> triangles) {
  if (triangles.size() > maxTriangles(ctx))
    throw DeviceError("bvh: " + std::to_string(triangles.size()) +
                      " triangles exceed the device limit of " + std::to_string(maxTriangles(ctx)) +
                      " (maxStorageBufferRange " +
                      std::to_string(ctx.caps().maxStorageBufferRange) + " bytes per binding)");
  Bvh bvh;
  bvh.nodeCount = static_cast<uint32_t>(tree.nodes.size());
  bvh.triangleCount = static_cast<uint32_t>(tree.leafTriangles.size());
  bvh.nodes = vk::Buffer(ctx, tree.nodes.size() * sizeof(gpu::bvh::BvhNode),
                         vk::MemoryUse::DeviceLocal, "bvh nodes", Bvh::kExtraUsage);
  bvh.nodes.uploadVector(tree.nodes);
  bvh.traversalNodes = vk::Buffer(ctx, tree.nodes.size() * sizeof(gpu::bvh::BvhTraversalNode),
                                  vk::MemoryUse::DeviceLocal, "bvh traversal nodes", Bvh::kExtraUsage);
  bvh.traversalNodes.uploadVector(quantizeNodes(tree.nodes));
  auto leaves = makeLeafTriangles(tree, vertices, triangles);
  bvh.leafData = vk::Buffer(ctx, leaves.size() * sizeof(gpu::bvh::BvhLeafTriangle),
                            vk::MemoryUse::DeviceLocal, "bvh leaf triangles", Bvh::kExtraUsage);
  bvh.leafData.uploadVector(leaves);
  bvh.quantized = quantizedTraversal(bvh.triangleCount);
  bvh.makeTexelViews(ctx);
  return bvh;
}

}  // namespace osr::bvh
