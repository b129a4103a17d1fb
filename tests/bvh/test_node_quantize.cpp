// Quantized traversal nodes (shared/bvh_quantize.h): every quantized child box contains its exact
// box (so no ray that enters the exact box misses the quantized one), stays within a few quanta of
// it, and an absent child is a box no ray enters; over random boxes at many scales and offsets,
// negative coordinates, flat boxes and the empty child.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bvh/node_quantize.h"

using namespace osr;
using gpu::bvh::BvhNode;

namespace {

BvhNode node(glm::vec3 aLo, glm::vec3 aHi, glm::vec3 bLo, glm::vec3 bHi) {
  BvhNode n{};
  n.aMin = aLo, n.aMax = aHi, n.bMin = bLo, n.bMax = bHi;
  n.a = 7, n.b = gpu::bvh::kBvhLeafFlag | 3;
  return n;
}

// Checks containment and tightness of one child; returns a message or "".
std::string checkChild(const gpu::bvh::BvhTraversalNode& q, int side, glm::vec3 lo, glm::vec3 hi, glm::vec3 nodeExtent) {
  bvh::QuantizedBox b = bvh::dequantizeChild(q, side);
  for (int k = 0; k < 3; ++k) {
    if (b.lo[k] > lo[k] || b.hi[k] < hi[k]) return "axis " + std::to_string(k) + " does not contain the exact box";
    // A quantum is at most extent / (255 - margin) * 2 (the scale is a power of two), plus the
    // origin's rounding (256 ulps of the min); the margin may add one more quantum.
    double quantum = 2.0 * std::max<double>(nodeExtent[k] + 256.0 * std::abs(lo[k]) * 1.2e-7, 1e-37) / 254.0;
    if (lo[k] - b.lo[k] > 2.01 * quantum || b.hi[k] - hi[k] > 2.01 * quantum)
      return "axis " + std::to_string(k) + " looser than two quanta";
  }
  return "";
}

}  // namespace

TEST(NodeQuantize, ChildBoxesAreContainedAndTight) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int checked = 0;
  for (float scale : {1e-6f, 1e-2f, 1.0f, 555.0f, 1e6f}) {
    for (float offset : {0.0f, 1.0f, -3.0f, 1e4f, -1e5f}) {
      for (int t = 0; t < 400; ++t) {
        glm::vec3 c[4];
        for (auto& p : c) p = glm::vec3(unit(rng), unit(rng), unit(rng)) * scale + offset * scale;
        glm::vec3 aLo = glm::min(c[0], c[1]), aHi = glm::max(c[0], c[1]);
        glm::vec3 bLo = glm::min(c[2], c[3]), bHi = glm::max(c[2], c[3]);
        if (t % 10 == 0) aHi.y = aLo.y;  // flat boxes (walls)
        BvhNode n = node(aLo, aHi, bLo, bHi);
        auto q = bvh::quantizeNode(n);
        glm::vec3 extent = glm::max(aHi, bHi) - glm::min(aLo, bLo);
        ASSERT_EQ(checkChild(q, 0, aLo, aHi, extent), "") << "scale " << scale << " offset " << offset << " case " << t;
        ASSERT_EQ(checkChild(q, 1, bLo, bHi, extent), "") << "scale " << scale << " offset " << offset << " case " << t;
        EXPECT_EQ(q.frame.w, n.a);
        EXPECT_EQ(q.boxes.x, n.b);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 5 * 5 * 400);
}

TEST(NodeQuantize, AbsentChildIsEmptyAndTheOtherKeepsItsBox) {
  // The builders' empty child (one triangle): an inverted box.
  BvhNode n = node({-1.0f, 2.0f, 3.0f}, {4.0f, 5.0f, 3.5f}, glm::vec3(1e30f), glm::vec3(-1e30f));
  auto q = bvh::quantizeNode(n);
  bvh::QuantizedBox b = bvh::dequantizeChild(q, 1);
  for (int k = 0; k < 3; ++k) EXPECT_GT(b.lo[k], b.hi[k]) << "axis " << k;
  EXPECT_EQ(checkChild(q, 0, n.aMin, n.aMax, n.aMax - n.aMin), "");
}
