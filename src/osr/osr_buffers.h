// The device buffers OSR's passes share, at the binding slots of shaders/shared/osr.h: the
// per-pixel G-buffer and running sums, the maps of the current pass (points, projections and
// clean radiance), and the per-chunk scratch of map tracing and denoising.
#pragma once
#include <cstdint>
#include <vector>

#include "bvh/bvh.h"
#include "osr/map_cache.h"
#include "common/error.h"
#include "render/film.h"
#include "scene_gpu/gpu_scene.h"
#include "shaders/shared/osr.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace osr::oneshot {

// Bytes of one map in the clean-map and one-shot buffers.
inline constexpr VkDeviceSize kCleanMapBytes = 3 * gpu::hemi::kMapTexels * sizeof(float);
inline constexpr VkDeviceSize kOneShotMapBytes =
    gpu::osr::kMapChannels * gpu::hemi::kMapTexels * sizeof(float);

struct OsrBuffers {
  // Sizes for a width x height film, at most maxMaps maps per pass and chunkMaps per chunk.
  // Per-pixel buffers and the clean maps are bound in windows (shared/osr.h), so their limit
  // is maxMemoryAllocationSize; the others are bound whole, within maxStorageBufferRange.
  // Throws DeviceError naming the limit and the size when a buffer does not fit.
  OsrBuffers(const vk::Context& ctx, uint32_t width, uint32_t height, uint32_t maxMaps,
             uint32_t chunkMaps);

  uint32_t maxMaps, chunkMaps;
  vk::Buffer frame;       // camera::CameraFrame
  vk::Buffer gbuffer;     // GBufferPixel[pixels]
  vk::Buffer accum;       // AccumPixel[pixels]
  vk::Buffer mapPoints;       // MapPoint[maxMaps]
  vk::Buffer mapProjections;  // MapProjection[maxMaps]
  vk::Buffer mapClean;    // float[maxMaps][3][32][32]
  vk::Buffer oneShot;     // float[chunkMaps][7][32][32]
  vk::Buffer mapStats;    // MapStats[chunkMaps]
  vk::Buffer netIn;       // float[chunkMaps][7][32][32]
  vk::Buffer netOut;      // float[chunkMaps][3][32][32]
  vk::Buffer mapCacheRefs;  // MapCacheRef[maxMaps]: zero (kMapCacheTrace) without a cache
};

// The parts of the windowed buffers one dispatch binds (shared/osr.h): pixels
// [pixelFirst, pixelFirst + pixelCount) of the G-buffer, accumulation and film; clean maps
// [mapFirst, mapFirst + mapCount); one-shot maps from chunk-relative map oneShotFirst on.
struct OsrWindow {
  uint32_t pixelFirst = 0, pixelCount = 0;
  uint32_t mapFirst = 0, mapCount = 0;
  uint32_t oneShotFirst = 0;
};

// Everything an OSR pass binds: OSR's buffers, the film, the BVH and the scene.
struct OsrBindings {
  const OsrBuffers* buffers = nullptr;
  const render::Film* film = nullptr;
  const bvh::Bvh* bvh = nullptr;
  const scene::GpuScene* scene = nullptr;
  const MapCache* cache = nullptr;  // the world-space map cache (a one-set one when off)
  // Fills every slot of the OSR layout by name (a pass's shader declares the ones it reads),
  // the windowed buffers with `window`.
  void fill(vk::Binder& binder, const OsrWindow& window) const;
};
std::vector<VkDescriptorType> osrDescriptorTypes();

}  // namespace osr::oneshot
