#include "bvh/node_quantize.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "shaders/shared/bvh_quantize.h"

namespace osr::bvh {

gpu::bvh::BvhTraversalNode quantizeNode(const gpu::bvh::BvhNode& node) { return gpu::bvh::bvhQuantizeNode(node); }

std::vector<gpu::bvh::BvhTraversalNode> quantizeNodes(std::span<const gpu::bvh::BvhNode> nodes) {
  std::vector<gpu::bvh::BvhTraversalNode> out(nodes.size());
  std::transform(nodes.begin(), nodes.end(), out.begin(), quantizeNode);
  return out;
}

QuantizedBox dequantizeChild(const gpu::bvh::BvhTraversalNode& node, int side) {
  QuantizedBox b;
  for (int k = 0; k < 3; ++k) {
    const uint32_t frame = node.frame[k];
    double o = std::bit_cast<float>(frame & ~gpu::bvh::kBvhQuantizeExponentBits);
    double s = std::ldexp(1.0, int(frame & gpu::bvh::kBvhQuantizeExponentBits) - 127);
    uint32_t q = node.boxes[k + 1] >> (side == 0 ? 0 : 16);
    b.lo[k] = o + double(q & 0xffu) * s;
    b.hi[k] = o + double((q >> 8) & 0xffu) * s;
  }
  return b;
}

}  // namespace osr::bvh
