#include "bvh/tree_stats.h"

#include <cstring>
#include <stdexcept>
#include <utility>

#include "bvh/aabb.h"

namespace osr::bvh {

namespace {

using gpu::bvh::BvhNode;
using gpu::bvh::kBvhLeafCountMask;
using gpu::bvh::kBvhLeafCountShift;
using gpu::bvh::kBvhLeafFirstMask;
using gpu::bvh::kBvhLeafFlag;

bool isLeaf(uint32_t ref) { return (ref & kBvhLeafFlag) != 0; }
uint32_t leafFirst(uint32_t ref) { return ref & kBvhLeafFirstMask; }
uint32_t leafCount(uint32_t ref) { return (ref >> kBvhLeafCountShift) & kBvhLeafCountMask; }

Aabb childBox(const BvhNode& n, int side) {
  Aabb b;
  b.lo = side == 0 ? n.aMin : n.bMin;
  b.hi = side == 0 ? n.aMax : n.bMax;
  return b;
}

}  // namespace

double sahCost(const HostBvh& tree) {
  if (tree.nodes.empty()) return 0.0;
  Aabb root = childBox(tree.nodes[0], 0);
  root.grow(childBox(tree.nodes[0], 1));
  double rootArea = root.area();
  if (!(rootArea > 0.0)) return 0.0;
  double sum = gpu::bvh::kSahNodeCost * rootArea;
  std::vector<uint32_t> stack = {0};
  while (!stack.empty()) {
    const BvhNode& n = tree.nodes[stack.back()];
    stack.pop_back();
    for (int side = 0; side < 2; ++side) {
      uint32_t ref = side == 0 ? n.a : n.b;
      double area = childBox(n, side).area();
      if (isLeaf(ref)) {
        sum += gpu::bvh::kSahTriangleCost * area * leafCount(ref);
      } else {
        sum += gpu::bvh::kSahNodeCost * area;
        stack.push_back(ref);
      }
    }
  }
  return sum / rootArea;
}

uint32_t depth(const HostBvh& tree) {
  if (tree.nodes.empty()) return 0;
  uint32_t deepest = 0;
  std::vector<std::pair<uint32_t, uint32_t>> stack = {{0u, 1u}};
  while (!stack.empty()) {
    auto [index, d] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, d);
    if (d > 4 * gpu::bvh::kBvhMaxDepth) break;  // a cycle; checkInvariants names it
    const BvhNode& n = tree.nodes[index];
    for (uint32_t ref : {n.a, n.b})
      if (!isLeaf(ref) && ref < tree.nodes.size()) stack.push_back({ref, d + 1});
  }
  return deepest;
}

std::string checkInvariants(const HostBvh& tree, std::span<const gpu::scene::Vertex> vertices,
                            std::span<const gpu::scene::Triangle> triangles) {
  if (tree.nodes.empty()) return "no nodes";
  std::vector<uint8_t> seenNode(tree.nodes.size(), 0);
  std::vector<uint32_t> seenTriangle(triangles.size(), 0);
  // (node, depth, the box its parent stores for it)
  struct Item {
    uint32_t node;
    uint32_t depth;
    Aabb box;
  };
  Aabb everything;
  everything.lo = glm::vec3(-std::numeric_limits<float>::max());
  everything.hi = glm::vec3(std::numeric_limits<float>::max());
  std::vector<Item> stack = {{0u, 1u, everything}};
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    if (it.node >= tree.nodes.size()) return "node reference " + std::to_string(it.node) + " out of range";
    if (seenNode[it.node]++) return "node " + std::to_string(it.node) + " reached twice";
    if (it.depth > gpu::bvh::kBvhMaxDepth)
      return "depth " + std::to_string(it.depth) + " exceeds kBvhMaxDepth";
    const BvhNode& n = tree.nodes[it.node];
    // Traversal intersects the hit leaves of a node as one range (shared/bvh.h).
    if (isLeaf(n.a) && isLeaf(n.b) && leafCount(n.a) && leafCount(n.b) &&
        leafFirst(n.b) != leafFirst(n.a) + leafCount(n.a))
      return "node " + std::to_string(it.node) + ": leaf b does not follow leaf a";
    for (int side = 0; side < 2; ++side) {
      uint32_t ref = side == 0 ? n.a : n.b;
      Aabb box = childBox(n, side);
      std::string where = "node " + std::to_string(it.node) + (side == 0 ? " child a" : " child b");
      if (!isLeaf(ref)) {
        if (!it.box.contains(box)) return where + ": box not inside its parent's box";
        stack.push_back({ref, it.depth + 1, box});
        continue;
      }
      if (leafCount(ref) == 0) continue;  // empty child
      if (!it.box.contains(box)) return where + ": leaf box not inside its parent's box";
      for (uint32_t i = leafFirst(ref); i < leafFirst(ref) + leafCount(ref); ++i) {
        if (i >= tree.leafTriangles.size()) return where + ": leaf entry out of range";
        uint32_t t = tree.leafTriangles[i];
        if (t >= triangles.size()) return where + ": triangle index out of range";
        if (seenTriangle[t]++) return "triangle " + std::to_string(t) + " in more than one leaf";
        for (uint32_t v : {triangles[t].v0, triangles[t].v1, triangles[t].v2}) {
          Aabb p;
          p.grow(vertices[v].position);
          if (!box.contains(p))
            return where + ": triangle " + std::to_string(t) + " not inside its leaf box";
        }
      }
    }
  }
  for (size_t t = 0; t < triangles.size(); ++t)
    if (!seenTriangle[t]) return "triangle " + std::to_string(t) + " in no leaf";
  return "";
}

HostBvh download(const Bvh& bvh) {
  if (!bvh.hasExactNodes)
    throw std::logic_error("bvh::download: the build kept no exact nodes (bvh::NodeForms::Both)");
  HostBvh tree;
  tree.nodes = bvh.nodes.downloadVector<BvhNode>(bvh.nodeCount);
  auto leaves = bvh.leafData.downloadVector<gpu::bvh::BvhLeafTriangle>(bvh.triangleCount);
  tree.leafTriangles.resize(leaves.size());
  for (size_t i = 0; i < leaves.size(); ++i) std::memcpy(&tree.leafTriangles[i], &leaves[i].v0.w, 4);
  return tree;
}

}  // namespace osr::bvh
