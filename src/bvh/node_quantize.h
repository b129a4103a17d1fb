// The traversal nodes (shared/bvh.h BvhTraversalNode) of BvhNodes on the host: the CPU builder's
// upload, and the reference the device build's are tested against. Same text as the device's
// (shared/bvh_quantize.h), so the same bits.
#pragma once
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/bvh.h"

namespace osr::bvh {

gpu::bvh::BvhTraversalNode quantizeNode(const gpu::bvh::BvhNode& node);
std::vector<gpu::bvh::BvhTraversalNode> quantizeNodes(std::span<const gpu::bvh::BvhNode> nodes);

// The box a quantized child stands for, o + q * s exactly (in double), for tests.
struct QuantizedBox {
  glm::dvec3 lo, hi;
};
QuantizedBox dequantizeChild(const gpu::bvh::BvhTraversalNode& node, int side);

}  // namespace osr::bvh
