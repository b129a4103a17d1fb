#include "bvh/radix_sort.h"

#include "bvh/build_pass.h"

namespace osr::bvh {

using namespace detail;

namespace {
std::vector<VkDescriptorType> radixTypes() {
  return storageAndTexelTypes(bb::kRadixBindingCount,
                              {bb::kRadixBindingKeyTexelsIn, bb::kRadixBindingValueTexelsIn});
}
std::vector<vk::SpecConstant> radixSpec(const vk::Context& ctx) {
  return {vk::specUint(bb::kRadixSpecTexels, wordTexelsCoverBindings(ctx) ? 1u : 0u)};
}
}  // namespace

RadixSort::RadixSort(const vk::Context& ctx)
    : histogram_(ctx, shaders::Id::bvh_radix_histogram, radixTypes(), sizeof(BuildPush),
                 radixSpec(ctx)),
      scatter_(ctx, shaders::Id::bvh_radix_scatter, radixTypes(), sizeof(BuildPush),
               radixSpec(ctx)),
      scan_(ctx) {}

uint64_t RadixSort::histogramBytes(uint32_t count) {
  return 4ull * bb::kRadixBins * std::max<uint64_t>(1, vk::groupCount(count, bb::kRadixChunk));
}

void RadixSort::record(VkCommandBuffer cmd, const Args& a, vk::GpuTimer* timer) const {
  uint32_t chunks = vk::groupCount(a.count, bb::kRadixChunk);
  uint32_t histWords = chunks * bb::kRadixBins;
  vk::BufferRange keys[2] = {a.keys, a.keysTmp}, values[2] = {a.values, a.valuesTmp};
  VkBufferView keyTexels[2] = {a.keyTexels, a.keyTmpTexels},
               valueTexels[2] = {a.valueTexels, a.valueTmpTexels};
  static_assert((bb::kRadixKeyBits + bb::kRadixBits - 1) / bb::kRadixBits % 2 == 0,
                "an even number of rounds leaves the result in keys/values");
  int src = 0;
  for (uint32_t shift = 0; shift < bb::kRadixKeyBits; shift += bb::kRadixBits, src ^= 1) {
    BuildPush pushed = push(a.count, shift);
    pushed.param2 = chunks;
    // Both pipelines bind the same buffers at the same slots.
    auto bind = [&](const vk::ComputePipeline& p) {
      vk::Binder(p)
          .set(bb::kRadixBindingKeysIn, keys[src])
          .set(bb::kRadixBindingValuesIn, values[src])
          .set(bb::kRadixBindingHist, a.histogram)
          .set(bb::kRadixBindingKeysOut, keys[src ^ 1])
          .set(bb::kRadixBindingValuesOut, values[src ^ 1])
          .setTexel(bb::kRadixBindingKeyTexelsIn, keyTexels[src])
          .setTexel(bb::kRadixBindingValueTexelsIn, valueTexels[src])
          .bind(cmd, pushed);
    };
    {
      vk::TimedScope scope(timer, cmd, "bvh_radix_histogram");
      bind(histogram_);
      histogram_.dispatch(cmd, groups(chunks));
      vk::computeBarrier(cmd);
    }
    {
      vk::TimedScope scope(timer, cmd, "bvh_scan");
      scan_.record(cmd, {a.histogram, a.partials, histWords});
    }
    vk::TimedScope scope(timer, cmd, "bvh_radix_scatter");
    bind(scatter_);
    scatter_.dispatch(cmd, groups(chunks));
    vk::computeBarrier(cmd);
  }
}

}  // namespace osr::bvh
