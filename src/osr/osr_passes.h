// The passes of OSR, one class each (shaders/osr_<pass>.comp, in the order a progressive pass
// records them: docs/osr.md). Each fills its own push struct of shared/osr.h from named
// arguments and records its dispatches and barrier (PassWithPush, osr_pass.h).
#pragma once
#include "osr/osr_pass.h"

namespace osr::oneshot {

class GBufferPass : public PassWithPush<gpu::osr::GBufferPush> {
 public:
  GBufferPass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  struct Args {
    uint32_t pass;        // progressive pass: its sub-pixel jitter
    uint32_t cameraRays;  // per pixel, for the lights seen directly
    float directWeight;   // the direct layer's weight of the pass
    PixelRange pixels;
  };
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, const Args& args) const;
};

class DirectPass : public PassWithPush<gpu::osr::DirectPush> {
 public:
  DirectPass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, uint32_t pass,
              uint32_t lightSamples, PixelRange pixels) const;
};

class MapsPass : public PassWithPush<gpu::osr::MapsPush> {
 public:
  MapsPass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  struct Args {
    gpu::osr::MapGrid grid;  // radius 0: the maps sit at the pixels of their MapPoints
    uint32_t pass;
    MapChunk maps;
    uint32_t pathsPerTexel;
  };
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, const Args& args) const;
};

// The per-map passes after tracing: statistics and network input, clean maps, projections.
class MapNormalizePass : public PassWithPush<gpu::osr::MapNormalizePush> {
 public:
  // byGroup: a workgroup per map, else an invocation per map (lib/osr_map_group.glsl).
  MapNormalizePass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch,
                   bool byGroup);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, MapChunk maps) const;
};

class MapDenoisePass : public PassWithPush<gpu::osr::MapDenoisePush> {
 public:
  // denoiser: gpu::osr::kDenoiser*; netOutput: how the U-Net's output becomes radiance.
  // byGroup: as MapNormalizePass.
  MapDenoisePass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch,
                 uint32_t denoiser, uint32_t netOutput, bool byGroup);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, MapChunk maps) const;
};

class MapProjectPass : public PassWithPush<gpu::osr::MapProjectPush> {
 public:
  // byGroup: as MapNormalizePass.
  MapProjectPass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch,
                 bool byGroup);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, MapChunk maps) const;
};

// The map cache's passes around one chunk of maps (docs/osr.md "The map cache"): lookup before
// tracing, claim (two phases) and store after the denoiser. They share one push struct.
struct MapCacheArgs {
  gpu::osr::MapGrid grid;
  MapChunk maps;
  uint32_t sets, generation, clock;
  uint32_t mapPass;  // map passes since the restart
  float cellScale;   // hash cell size in grid spacings
  uint32_t maturePasses;  // OsrSettings::mapCacheMaturePasses
};

class MapCacheLookupPass : public PassWithPush<gpu::osr::MapCachePush> {
 public:
  MapCacheLookupPass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, const MapCacheArgs& args) const;
};

class MapCacheClaimPass : public PassWithPush<gpu::osr::MapCachePush> {
 public:
  MapCacheClaimPass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  // Both phases: claim, then keep the claims won.
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, const MapCacheArgs& args) const;
};

class MapCacheStorePass : public PassWithPush<gpu::osr::MapCachePush> {
 public:
  MapCacheStorePass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, const MapCacheArgs& args) const;
};

// The two passes that read the maps at each pixel (grid: the current maps').
struct MapPixelArgs {
  gpu::osr::MapGrid grid;
  uint32_t pass;
  uint32_t samples;  // glossy directions (composite) or residual paths (residual) per pixel
  float passWeight;  // w_k
  PixelRange pixels;
  float momentWeight = 0.f;  // composite: w_k where the pass traced its maps (CompositePush)
  float guideShare = 0.f;    // residual: first directions drawn from the maps (ResidualPush)
};

class CompositePass : public PassWithPush<gpu::osr::CompositePush> {
 public:
  CompositePass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, const MapPixelArgs& args) const;
};

class ResidualPass : public PassWithPush<gpu::osr::ResidualPush> {
 public:
  ResidualPass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, const MapPixelArgs& args) const;
};

class ResolvePass : public PassWithPush<gpu::osr::ResolvePush> {
 public:
  ResolvePass(const vk::Context& ctx, uint32_t sceneFeatures, bool sceneTexelFetch);
  // residualBlend: the accumulated residual's weight (0..1), or < 0 to measure it per pixel
  // with the residual's variance weighted by residualNoiseWeight.
  void record(VkCommandBuffer cmd, const OsrBindings& bindings, float residualBlend,
              float residualNoiseWeight, PixelRange pixels) const;
};

}  // namespace osr::oneshot
