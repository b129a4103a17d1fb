// The device buffers OSR's passes share, at the binding slots of shaders/shared/osr.h: the
// per-pixel G-buffer and running sums, the maps of the current pass (records and clean
// radiance), and the per-chunk scratch of map tracing and denoising.
#pragma once
#include <cstdint>
#include <vector>

#include "bvh/bvh.h"
#include "common/error.h"
#include "render/film.h"
#include "scene_gpu/gpu_scene.h"
#include "shaders/shared/osr.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace osr::oneshot {

struct OsrBuffers {
  // Sizes for a width x height film, at most maxMaps maps per pass and chunkMaps per chunk.
  // Throws DeviceError naming maxStorageBufferRange when a buffer cannot be bound whole.
  OsrBuffers(const vk::Context& ctx, uint32_t width, uint32_t height, uint32_t maxMaps,
             uint32_t chunkMaps);

  uint32_t maxMaps, chunkMaps;
  vk::Buffer frame;       // camera::CameraFrame
  vk::Buffer gbuffer;     // GBufferPixel[pixels]
  vk::Buffer accum;       // AccumPixel[pixels]
  vk::Buffer mapRecords;  // MapRecord[maxMaps]
  vk::Buffer mapClean;    // float[maxMaps][3][32][32]
  vk::Buffer oneShot;     // float[chunkMaps][7][32][32]
  vk::Buffer mapStats;    // MapStats[chunkMaps]
  vk::Buffer netIn;       // float[chunkMaps][7][32][32]
  vk::Buffer netOut;      // float[chunkMaps][3][32][32]
};

// Everything an OSR pass binds: OSR's buffers, the film, the BVH and the scene.
struct OsrBindings {
  const OsrBuffers* buffers = nullptr;
  const render::Film* film = nullptr;
  const bvh::Bvh* bvh = nullptr;
  const scene::GpuScene* scene = nullptr;
  // Fills every slot of the OSR layout by name (a pass's shader declares the ones it reads).
  void fill(vk::Binder& binder) const;
};
std::vector<VkDescriptorType> osrDescriptorTypes();

}  // namespace osr::oneshot
