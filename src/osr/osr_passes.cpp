#include "osr/osr_passes.h"

namespace osr::oneshot {

namespace o = gpu::osr;
using shaders::Id;

namespace {
const o::MapGrid kNoMaps{};  // for passes that read no clean maps

// CompositePush and ResidualPush: the same fields in the same order but the last, which
// each pass takes from its own argument.
template <class Push>
Push mapPixelPush(const MapPixelArgs& a, const OsrWindow& w, float last) {
  return Push{a.grid,     a.pass,    w.pixelFirst, w.pixelCount,
              w.mapFirst, a.samples, a.passWeight, last};
}
o::MapCachePush mapCachePush(const MapCacheArgs& a, const OsrWindow& w, uint32_t phase) {
  o::MapCachePush p{};
  p.grid = a.grid;
  p.mapOffset = w.mapFirst;
  p.mapCount = w.mapCount;
  p.gbufferWindowOffset = w.pixelFirst;
  p.sets = a.sets;
  p.generation = a.generation;
  p.clock = a.clock;
  p.mapPass = a.mapPass;
  p.phase = phase;
  p.cellScale = a.cellScale;
  p.maturePasses = a.maturePasses;
  return p;
}
}  // namespace

GBufferPass::GBufferPass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_gbuffer, Domain::Pixels, features, texelFetch) {}

void GBufferPass::record(VkCommandBuffer cmd, const OsrBindings& b, const Args& a) const {
  recordPixels(cmd, b, kNoMaps, a.pixels, [&](const OsrWindow& w) {
    return o::GBufferPush{a.pass, w.pixelFirst, w.pixelCount, a.cameraRays, a.directWeight};
  });
}

DirectPass::DirectPass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_direct, Domain::Pixels, features, texelFetch) {}

void DirectPass::record(VkCommandBuffer cmd, const OsrBindings& b, uint32_t pass,
                        uint32_t lightSamples, PixelRange pixels) const {
  recordPixels(cmd, b, kNoMaps, pixels, [&](const OsrWindow& w) {
    return o::DirectPush{pass, w.pixelFirst, w.pixelCount, lightSamples};
  });
}

MapsPass::MapsPass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_maps, Domain::MapTexels, features, texelFetch) {}

void MapsPass::record(VkCommandBuffer cmd, const OsrBindings& b, const Args& a) const {
  recordMaps(cmd, b, a.grid, a.maps, [&](const OsrWindow& w) {
    return o::MapsPush{a.grid, a.pass, w.mapFirst, w.mapCount, a.pathsPerTexel, w.pixelFirst};
  });
}

namespace {
// The domain and specialization of a pass over whole maps (lib/osr_map_group.glsl).
Domain mapDomain(bool byGroup) { return byGroup ? Domain::MapGroups : Domain::Maps; }
vk::SpecConstant mapLayout(bool byGroup) {
  return vk::specUint(o::kOsrSpecMapByGroup, byGroup ? 1u : 0u);
}
}  // namespace

MapNormalizePass::MapNormalizePass(const vk::Context& ctx, uint32_t features, bool texelFetch,
                                   bool byGroup)
    : PassWithPush(ctx, Id::osr_map_normalize, mapDomain(byGroup), features, texelFetch,
                   {mapLayout(byGroup)}) {}

void MapNormalizePass::record(VkCommandBuffer cmd, const OsrBindings& b, MapChunk maps) const {
  recordMaps(cmd, b, kNoMaps, maps,
             [](const OsrWindow& w) { return o::MapNormalizePush{w.mapCount}; });
}

MapDenoisePass::MapDenoisePass(const vk::Context& ctx, uint32_t features, bool texelFetch,
                               uint32_t denoiser, uint32_t netOutput, bool byGroup)
    : PassWithPush(ctx, Id::osr_map_denoise, mapDomain(byGroup), features, texelFetch,
                   {vk::specUint(o::kOsrSpecDenoiser, denoiser),
                    vk::specUint(o::kOsrSpecNetOutput, netOutput), mapLayout(byGroup)}) {}

void MapDenoisePass::record(VkCommandBuffer cmd, const OsrBindings& b, MapChunk maps) const {
  recordMaps(cmd, b, kNoMaps, maps, [](const OsrWindow& w) { return o::MapDenoisePush{w.mapFirst, w.mapCount}; });
}

MapProjectPass::MapProjectPass(const vk::Context& ctx, uint32_t features, bool texelFetch,
                               bool byGroup)
    : PassWithPush(ctx, Id::osr_map_project, mapDomain(byGroup), features, texelFetch,
                   {mapLayout(byGroup)}) {}

void MapProjectPass::record(VkCommandBuffer cmd, const OsrBindings& b, MapChunk maps) const {
  recordMaps(cmd, b, kNoMaps, maps,
             [](const OsrWindow& w) { return o::MapProjectPush{w.mapFirst, w.mapCount}; });
}

MapCacheLookupPass::MapCacheLookupPass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_cache_lookup, Domain::MapTexels, features, texelFetch) {}

void MapCacheLookupPass::record(VkCommandBuffer cmd, const OsrBindings& b,
                                const MapCacheArgs& a) const {
  recordMaps(cmd, b, a.grid, a.maps,
             [&](const OsrWindow& w) { return mapCachePush(a, w, 0); });
}

MapCacheClaimPass::MapCacheClaimPass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_cache_claim, Domain::Maps, features, texelFetch) {}

void MapCacheClaimPass::record(VkCommandBuffer cmd, const OsrBindings& b,
                               const MapCacheArgs& a) const {
  for (uint32_t phase = 0; phase < 2; ++phase)
    recordMaps(cmd, b, a.grid, a.maps,
               [&](const OsrWindow& w) { return mapCachePush(a, w, phase); });
}

MapCacheStorePass::MapCacheStorePass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_cache_store, Domain::MapTexels, features, texelFetch) {}

void MapCacheStorePass::record(VkCommandBuffer cmd, const OsrBindings& b,
                               const MapCacheArgs& a) const {
  recordMaps(cmd, b, a.grid, a.maps,
             [&](const OsrWindow& w) { return mapCachePush(a, w, 0); });
}

CompositePass::CompositePass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_composite, Domain::Pixels, features, texelFetch) {}

void CompositePass::record(VkCommandBuffer cmd, const OsrBindings& b, const MapPixelArgs& a) const {
  recordPixels(cmd, b, a.grid, a.pixels, [&](const OsrWindow& w) {
    return mapPixelPush<o::CompositePush>(a, w, a.momentWeight);
  });
}

ResidualPass::ResidualPass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_residual, Domain::Pixels, features, texelFetch) {}

void ResidualPass::record(VkCommandBuffer cmd, const OsrBindings& b, const MapPixelArgs& a) const {
  recordPixels(cmd, b, a.grid, a.pixels, [&](const OsrWindow& w) {
    return mapPixelPush<o::ResidualPush>(a, w, a.guideShare);
  });
}

ResolvePass::ResolvePass(const vk::Context& ctx, uint32_t features, bool texelFetch)
    : PassWithPush(ctx, Id::osr_resolve, Domain::Pixels, features, texelFetch) {}

void ResolvePass::record(VkCommandBuffer cmd, const OsrBindings& b, float residualBlend,
                         float residualNoiseWeight, PixelRange pixels) const {
  recordPixels(cmd, b, kNoMaps, pixels, [&](const OsrWindow& w) {
    return o::ResolvePush{w.pixelFirst, w.pixelCount, residualBlend, residualNoiseWeight};
  });
}

}  // namespace osr::oneshot
