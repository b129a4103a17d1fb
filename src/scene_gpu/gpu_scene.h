// The scene on the device: one storage buffer per kind of scene data, uploaded once, in the
// layout of shaders/shared/scene.h. Passes place them with bind() / bindTexels() at the base
// slots they give shaders/lib/scene.glsl (OSR_SCENE_BINDING, OSR_SCENE_TEXEL_BINDING).
#pragma once
#include <array>

#include "scene/scene.h"
#include "vk/binder.h"
#include "vk/buffer.h"
#include "vk/buffer_view.h"
#include "vk/context.h"

namespace osr::scene {

class GpuScene {
 public:
  // Uploads `scene` (and `env`, optional). Buffers are never empty: an empty list is padded with
  // one zeroed element (the counts in SceneInfo say how many are real). Throws DeviceError naming
  // the buffer's size and the device limit when a shader could not read all of it: storage
  // buffers reach maxStorageBufferRange; vertices, triangles and materials, which shading reads
  // by texel fetch, reach maxTexelBufferElements texels where that is further (2 GiB on
  // lavapipe: about 60M triangles).
  GpuScene(const vk::Context& ctx, const Scene& scene, const Environment* env = nullptr);

  // Declared in binding order.
  vk::Buffer vertices;
  vk::Buffer triangles;
  vk::Buffer materials;
  vk::Buffer textureInfos;
  vk::Buffer texels;
  vk::Buffer lights;
  vk::Buffer emissive;
  vk::Buffer info;
  vk::Buffer environment;
  vk::Buffer environmentCdf;
  uint32_t triangleCount = 0;
  uint32_t vertexCount = 0;
  // kSceneFeature* bits (shaders/shared/scene.h) of what this scene uses, for passes to
  // specialise on: on lavapipe a branch costs every lane whether any lane takes it, so code a
  // scene does not need is compiled out (docs/device_notes.md, "What lavapipe charges for").
  uint32_t features = 0;

  // RGBA32UI views of vertices, triangles, materials in kSceneTexelBinding* order, for passes
  // that define OSR_SCENE_TEXEL_BINDING. texelFetch: whether they read them (the views cover
  // at most maxTexelBufferElements texels; past that the shaders must read storage buffers).
  std::array<VkBufferView, gpu::kSceneTexelBindingCount> texelViews() const;
  bool texelFetch = false;

  // The buffers by slot: element kSceneBinding* is that slot's buffer (vertices, triangles and
  // materials cut at maxStorageBufferRange: past it, passes read them by texel fetch).
  std::array<vk::BufferRange, gpu::kSceneBindingCount> bindings() const;
  // Sets slots base + kSceneBinding* (base: the pass's OSR_SCENE_BINDING).
  void bind(vk::Binder& binder, uint32_t base) const;
  // Sets slots base + kSceneTexelBinding* (base: the pass's OSR_SCENE_TEXEL_BINDING).
  void bindTexels(vk::Binder& binder, uint32_t base) const;
  // Total bytes uploaded.
  uint64_t bytes() const;

 private:
  vk::BufferView vertexTexels_, triangleTexels_, materialTexels_;
  uint64_t storageRange_ = 0;  // the device's maxStorageBufferRange
};

}  // namespace osr::scene
