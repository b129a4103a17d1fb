#include "scene_gpu/gpu_scene.h"

#include <utility>

#include "common/error.h"
#include "scene/environment.h"

namespace osr::scene {

namespace {

// The most bytes a shader can read of one scene buffer, and the device limit's name. Storage
// bindings reach maxStorageBufferRange (128 MiB on lavapipe). The buffers that shading reads by
// texel fetch (vertices, triangles, materials: `texelRead`) reach further where the device's
// texel views are the longer reach (2 GiB on lavapipe: maxTexelBufferElements RGBA32UI texels,
// also its maxMemoryAllocationSize); their storage bindings then hold only the first
// maxStorageBufferRange bytes (GpuScene::bindings), which no shading pass reads past.
std::pair<uint64_t, std::string> readLimit(const vk::Context& ctx, bool texelRead) {
  const vk::Capabilities& caps = ctx.caps();
  uint64_t texelBytes = uint64_t(caps.maxTexelBufferElements) * 16;
  if (texelRead && texelBytes > caps.maxStorageBufferRange) {
    if (caps.maxMemoryAllocationSize < texelBytes) return {caps.maxMemoryAllocationSize, "maxMemoryAllocationSize"};
    return {texelBytes, "maxTexelBufferElements x 16 bytes"};
  }
  return {caps.maxStorageBufferRange, "maxStorageBufferRange"};
}

// One device-local buffer holding `data` (or one zeroed T when empty). Refuses sizes past what
// a shader can read of it (readLimit) in one line naming the size and the limit.
template <class T>
vk::Buffer upload(const vk::Context& ctx, const std::vector<T>& data, const std::string& what,
                  const std::string& scenePath, bool texelRead = false) {
  uint64_t bytes = uint64_t(std::max<size_t>(data.size(), 1)) * sizeof(T);
  auto [limit, limitName] = readLimit(ctx, texelRead);
  if (bytes > limit)
    throw DeviceError(scenePath + ": scene too large for the device: the " + what +
                      " buffer needs " + std::to_string((bytes + (1 << 20) - 1) >> 20) + " MiB (" +
                      std::to_string(data.size()) + " elements), more than the device's " +
                      limitName + " of " + std::to_string(limit >> 20) + " MiB (" +
                      ctx.caps().deviceName + ")");
  vk::Buffer buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "scene " + what,
                    texelRead ? VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT : 0);
  if (data.empty()) {
    T zero{};
    buffer.upload(&zero, sizeof(T));
  } else {
    buffer.uploadVector(data);
  }
  return buffer;
}

}  // namespace

GpuScene::GpuScene(const vk::Context& ctx, const Scene& scene, const Environment* env) {
  const std::string& path = scene.path;
  // Texels of every texture back to back; TextureInfo says where each one starts.
  std::vector<gpu::TextureInfo> infos;
  uint64_t texelCount = 0;
  for (const Texture& t : scene.textures) texelCount += t.texels.size();
  uint64_t texelBytes = texelCount * 4;
  if (texelBytes > ctx.caps().maxStorageBufferRange)
    throw DeviceError(path + ": scene too large for the device: its textures need " +
                      std::to_string((texelBytes + (1 << 20) - 1) >> 20) +
                      " MiB, more than the device's maxStorageBufferRange of " +
                      std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB (" +
                      ctx.caps().deviceName + ")");
  std::vector<uint32_t> allTexels;
  allTexels.reserve(texelCount);
  for (const Texture& t : scene.textures) {
    infos.push_back({uint32_t(allTexels.size()), t.width, t.height, t.wrap});
    allTexels.insert(allTexels.end(), t.texels.begin(), t.texels.end());
  }

  gpu::SceneInfo si{};
  si.triangleCount = uint32_t(scene.triangles.size());
  si.emissiveCount = uint32_t(scene.emissive.size());
  si.lightCount = uint32_t(scene.lights.size());
  si.envScale = 1.0f;
  si.emissivePower = scene.emissivePower;
  si.vertexAttributes = 0;
  if (!scene.attributes.empty()) {
    // After the texels (shared/scene.h VertexAttributes): word 0 stays a texel or padding.
    if (allTexels.empty()) allTexels.push_back(0u);
    si.vertexAttributes = uint32_t(allTexels.size());
    const uint32_t* words = reinterpret_cast<const uint32_t*>(scene.attributes.data());
    allTexels.insert(allTexels.end(), words, words + 4 * scene.attributes.size());
  }
  si.boundsMin = glm::vec4(scene.boundsMin, 0.0f);
  si.boundsMax = glm::vec4(scene.boundsMax, 0.0f);
  std::vector<glm::vec4> envTexels;
  std::vector<float> envCdf;
  if (env && env->width > 0 && env->height > 0) {
    si.envWidth = env->width;
    si.envHeight = env->height;
    envTexels = env->texels;
    envCdf = scene::environmentCdf(*env);
  }

  vertices = upload(ctx, scene.vertices, "vertex", path, true);
  triangles = upload(ctx, scene.triangles, "triangle", path, true);
  materials = upload(ctx, scene.materials, "material", path, true);
  textureInfos = upload(ctx, infos, "texture info", path);
  texels = upload(ctx, allTexels, "texel", path);
  lights = upload(ctx, scene.lights, "light", path);
  emissive = upload(ctx, scene.emissive, "emissive triangle", path);
  info = upload(ctx, std::vector<gpu::SceneInfo>{si}, "info", path);
  environment = upload(ctx, envTexels, "environment", env ? env->path : path);
  environmentCdf = upload(ctx, envCdf, "environment cdf", env ? env->path : path);
  triangleCount = si.triangleCount;
  vertexCount = uint32_t(scene.vertices.size());
  for (const gpu::Material& m : scene.materials) {
    if (m.flags & (gpu::kMaterialAlphaMask | gpu::kMaterialAlphaBlend))
      features |= gpu::kSceneFeatureAlphaTest;
    if (m.flags & gpu::kMaterialAlphaBlend) features |= gpu::kSceneFeatureAlphaBlend;
    if (m.transmission > 0.0f) features |= gpu::kSceneFeatureTransmission;
    bool absorbs = m.thickness > 0.0f && m.attenuationDistance > 0.0f &&
                   glm::any(glm::lessThan(m.attenuationColor, glm::vec3(1.0f)));
    if (m.clearcoat > 0.0f || glm::any(glm::greaterThan(m.sheenColor, glm::vec3(0.0f))) ||
        m.diffuseTransmission > 0.0f || m.anisotropyStrength > 0.0f || m.iridescence > 0.0f ||
        absorbs)
      features |= gpu::kSceneFeatureLayers;
  }
  if (!scene.attributes.empty()) features |= gpu::kSceneFeatureVertexAttributes;
  if (!scene.textures.empty()) features |= gpu::kSceneFeatureTextures;
  if (!scene.lights.empty()) features |= gpu::kSceneFeaturePunctual;
  if (si.envWidth > 0) features |= gpu::kSceneFeatureEnvironment;

  bool coversV, coversT, coversM;
  vertexTexels_ = vk::BufferView::uintTexels(ctx, vertices, "scene vertex texels", &coversV);
  triangleTexels_ = vk::BufferView::uintTexels(ctx, triangles, "scene triangle texels", &coversT);
  materialTexels_ = vk::BufferView::uintTexels(ctx, materials, "scene material texels", &coversM);
  texelFetch = coversV && coversT && coversM;
  storageRange_ = ctx.caps().maxStorageBufferRange;
}

// Texels per element that shaders/lib/scene.glsl reads (Material's layout is asserted in
// shaders/shared/scene.h against its kMaterialWord* constants).
static_assert(sizeof(gpu::VertexAttributes) == 16, "4 texel words per vertex in lib/scene.glsl");
static_assert(sizeof(gpu::Vertex) == 32 && sizeof(gpu::Triangle) == 16 &&
                  sizeof(gpu::Material) == 16 * gpu::kMaterialTexels,
              "texel counts in shaders/lib/scene.glsl");

std::array<vk::BufferRange, gpu::kSceneBindingCount> GpuScene::bindings() const {
  std::array<vk::BufferRange, gpu::kSceneBindingCount> b;
  // See readLimit: a buffer past maxStorageBufferRange is read by texel fetch.
  auto storage = [&](const vk::Buffer& buf) {
    return vk::BufferRange(buf, 0, std::min<VkDeviceSize>(buf.size(), storageRange_ / 16 * 16));
  };
  b[gpu::kSceneBindingVertices] = storage(vertices);
  b[gpu::kSceneBindingTriangles] = storage(triangles);
  b[gpu::kSceneBindingMaterials] = storage(materials);
  b[gpu::kSceneBindingTextureInfos] = textureInfos;
  b[gpu::kSceneBindingTexels] = texels;
  b[gpu::kSceneBindingLights] = lights;
  b[gpu::kSceneBindingEmissive] = emissive;
  b[gpu::kSceneBindingInfo] = info;
  b[gpu::kSceneBindingEnvironment] = environment;
  b[gpu::kSceneBindingEnvironmentCdf] = environmentCdf;
  return b;
}

std::array<VkBufferView, gpu::kSceneTexelBindingCount> GpuScene::texelViews() const {
  std::array<VkBufferView, gpu::kSceneTexelBindingCount> v;
  v[gpu::kSceneTexelBindingVertices] = vertexTexels_.handle();
  v[gpu::kSceneTexelBindingTriangles] = triangleTexels_.handle();
  v[gpu::kSceneTexelBindingMaterials] = materialTexels_.handle();
  return v;
}

void GpuScene::bind(vk::Binder& binder, uint32_t base) const {
  const auto b = bindings();
  for (uint32_t i = 0; i < gpu::kSceneBindingCount; ++i) binder.set(base + i, b[i]);
}

void GpuScene::bindTexels(vk::Binder& binder, uint32_t base) const {
  const auto v = texelViews();
  for (uint32_t i = 0; i < gpu::kSceneTexelBindingCount; ++i) binder.setTexel(base + i, v[i]);
}

uint64_t GpuScene::bytes() const {
  uint64_t total = 0;
  for (const vk::BufferRange& r : bindings()) total += r.buffer->size();  // whole buffers
  return total;
}

}  // namespace osr::scene
