// glTF 2.0 -> Scene: tinygltf parses the file (and decodes images with stb_image); this file
// checks everything tinygltf leaves unchecked (accessor ranges, indices, finite positions,
// images), applies every node transform and flattens the meshes into world-space triangles.
#include <tiny_gltf.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <array>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "common/error.h"
#include "common/hdr_check.h"
#include "common/input_file.h"
#include "scene/emissive.h"
#include "scene/scene.h"

namespace osr::scene {

gpu::Material defaultMaterial() {
  gpu::Material m{};
  m.baseColor = glm::vec4(1.0f);
  m.emission = glm::vec3(0.0f);
  m.roughness = 1.0f;
  m.specularColor = glm::vec3(1.0f);
  m.metallic = 1.0f;
  m.specular = 1.0f;
  m.ior = 1.5f;
  m.transmission = 0.0f;
  m.alphaCutoff = 0.5f;
  m.baseColorTexture = gpu::kNoTexture;
  m.metallicRoughnessTexture = gpu::kNoTexture;
  m.normalTexture = gpu::kNoTexture;
  m.emissiveTexture = gpu::kNoTexture;
  m.transmissionTexture = gpu::kNoTexture;
  m.specularTexture = gpu::kNoTexture;
  m.specularColorTexture = gpu::kNoTexture;
  m.flags = 0;
  m.normalScale = 1.0f;
  m.clearcoatNormalScale = 1.0f;
  m.attenuationColor = glm::vec3(1.0f);
  m.diffuseTransmissionColor = glm::vec3(1.0f);
  m.clearcoatTexture = m.clearcoatRoughnessTexture = m.clearcoatNormalTexture = gpu::kNoTexture;
  m.sheenColorTexture = m.sheenRoughnessTexture = gpu::kNoTexture;
  m.diffuseTransmissionTexture = m.diffuseTransmissionColorTexture = gpu::kNoTexture;
  m.anisotropyTexture = gpu::kNoTexture;
  m.iridescenceIor = 1.3f;
  m.iridescenceThicknessMinimum = 100.0f;
  m.iridescenceThicknessMaximum = 400.0f;
  m.iridescenceTexture = m.iridescenceThicknessTexture = gpu::kNoTexture;
  return m;
}

namespace {

// tinygltf's file callbacks with the check of the scene file itself: a buffer or image URI
// naming a folder was "out of memory loading the scene" (the stream size of a folder), one
// naming a pipe blocked forever (tinygltf's FileExists opens the file to see if it exists).
bool fileExists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::exists(path, ec);
}

bool readRegularFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* userData) {
  if (auto problem = inputFileProblem(path)) {
    if (err) *err += *problem;
    return false;
  }
  return tinygltf::ReadWholeFile(out, err, path, userData);
}

// The largest texture osr-vk reads: 16384 texels a side (GPUs' usual largest 2D image), which
// a few bytes of PNG header can claim many times over (a 3.9 KB scene's 1024 x 262144 PNG made
// stb_image allocate 1 GiB).
constexpr int kMaxTextureSide = 16384;

// tinygltf's image decoder (stb_image) after two checks: the size the image's header claims,
// and the Radiance .hdr check (stb_image tells formats by content, not by name, and would loop
// forever on a .hdr with a run of length 0).
bool loadImageChecked(tinygltf::Image* image, const int index, std::string* err, std::string* warn,
                      int width, int height, const unsigned char* bytes, int size, void*) {
  auto refuse = [&](const std::string& problem) {
    if (err) *err += "image " + std::to_string(index) + ": " + problem;
    return false;
  };
  if (auto problem = radianceHdrProblem(bytes, size_t(std::max(size, 0)))) return refuse(*problem);
  int w = 0, h = 0, comps = 0;
  if (stbi_info_from_memory(bytes, size, &w, &h, &comps) &&
      (w > kMaxTextureSide || h > kMaxTextureSide))
    return refuse(std::to_string(w) + " x " + std::to_string(h) + " texels, more than osr-vk reads (" +
                  std::to_string(kMaxTextureSide) + " a side)");
  return tinygltf::LoadImageData(image, index, err, warn, width, height, bytes, size, nullptr);
}

// Extensions whose data the loader uses. Everything else is warned about once and ignored.
const std::set<std::string> kSupportedExtensions = {
    "KHR_materials_emissive_strength", "KHR_materials_specular", "KHR_materials_ior",
    "KHR_materials_transmission", "KHR_materials_clearcoat", "KHR_materials_sheen",
    "KHR_materials_volume", "KHR_materials_diffuse_transmission", "KHR_materials_anisotropy",
    "KHR_materials_iridescence",
    "KHR_lights_punctual",
    // Integer and normalized attribute types: every accessor is read through one converter.
    "KHR_mesh_quantization",
    // Baked into the vertex uvs, one transform per material (see Loader::noteUvTransform).
    "KHR_texture_transform",
    // Metadata (licence, authoring tool) with nothing to render: the ratified name and the
    // draft's, which Khronos sample models still carry.
    "KHR_xmp_json_ld", "KHR_xmp"};

// Luminous efficacy used to turn glTF's photometric light units into the radiometric ones of
// emissive radiance (the constant Blender's glTF I/O uses, PBR_WATTS_TO_LUMENS = 683 lm/W):
// point/spot candela / 683 = W/sr, directional lux / 683 = W/m^2.
constexpr float kLumensPerWatt = 683.0f;

size_t componentBytes(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

// A checked view of an accessor's elements: every element lies inside its buffer view.
struct AccessorData {
  const uint8_t* data = nullptr;  // nullptr: no buffer view, every element is zero (spec)
  size_t stride = 0;
  size_t count = 0;
  int componentType = 0;
  int components = 0;
  bool normalized = false;

  double component(size_t element, int c) const {
    if (!data) return 0.0;
    const uint8_t* p = data + element * stride + c * componentBytes(componentType);
    switch (componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? *p / 255.0 : *p;
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        double v = static_cast<int8_t>(*p);
        return normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_INT: {
        int32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
    }
    return 0.0;
  }
  uint32_t index(size_t element) const { return static_cast<uint32_t>(component(element, 0)); }
  std::shared_ptr<std::vector<uint8_t>>
      owned;  // densified sparse accessor, when `data` points here
  glm::vec2 vec2(size_t i) const { return {component(i, 0), component(i, 1)}; }
  glm::vec3 vec3(size_t i) const { return {component(i, 0), component(i, 1), component(i, 2)}; }
};

glm::vec3 toVec3(const std::vector<double>& v, glm::vec3 fallback) {
  return v.size() >= 3 ? glm::vec3(v[0], v[1], v[2]) : fallback;
}

double number(const tinygltf::Value& object, const char* key, double fallback) {
  if (!object.IsObject() || !object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

// An index or set number inside an extension object: whole and within int's range, else
// nullopt (converting 1e30 to int is undefined behaviour).
std::optional<int> wholeNumber(const tinygltf::Value& object, const char* key, int fallback) {
  const double v = number(object, key, fallback);
  if (!(v >= -2147483648.0 && v <= 2147483647.0) || v != std::floor(v)) return std::nullopt;
  return int(v);
}

class Loader {
 public:
  Loader(const std::string& path, Scene& scene) : path_(path), scene_(scene) {}

  void run() {
    parse();
    checkExtensions();
    for (size_t i = 0; i < model_.materials.size(); ++i)
      scene_.materials.push_back(material(int(i)));
    readAnimations();
    traverseScenes();
    if (scene_.triangles.empty()) fail("the scene has no triangles");
    // Kept only when some primitive has COLOR_0 or TEXCOORD_1 (shaders read none otherwise).
    if (!hasAttributes_) std::vector<gpu::VertexAttributes>().swap(scene_.attributes);
    if (defaultMaterialIndex_ >= 0 || scene_.materials.empty()) {
      if (defaultMaterialIndex_ < 0) defaultMaterialIndex_ = int(scene_.materials.size());
      scene_.materials.push_back(defaultMaterial());
    }
    updateBounds(scene_);
    collectEmissive(scene_);
    for (const std::string& w : scene_.warnings)
      std::fprintf(stderr, "osr-vk: warning: %s: %s\n", path_.c_str(), w.c_str());
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(path_ + ": " + problem);
  }

  // Collected while loading and printed once the scene loaded, so that a refused file gets
  // exactly one line on stderr.
  void warn(const std::string& message) {
    if (warned_.insert(message).second) scene_.warnings.push_back(message);
  }

  // --- Parsing ------------------------------------------------------------------------------

  void parse() {
    namespace fs = std::filesystem;
    if (auto problem = inputFileProblem(path_)) fail(*problem);
    std::ifstream in(path_, std::ios::binary);
    if (!in) fail("cannot open file");
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                     std::istreambuf_iterator<char>());
    if (bytes.empty()) fail("file is empty");
    // tinygltf takes 32-bit sizes.
    if (bytes.size() >= (uint64_t(1) << 32))
      fail("file is larger than 4 GiB, which tinygltf cannot read");
    std::string baseDir = fs::path(path_).parent_path().string();
    if (baseDir.empty()) baseDir = ".";

    tinygltf::TinyGLTF gltf;
    gltf.SetFsCallbacks({&fileExists, &tinygltf::ExpandFilePath, &readRegularFile,
                         &tinygltf::WriteWholeFile, nullptr});
    gltf.SetImageLoader(&loadImageChecked, nullptr);
    std::string err, warn;
    bool ok;
    // Decide by content, not by name: a .glb starts with the magic "glTF".
    if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
      checkGlbHeader(bytes);
      ok = gltf.LoadBinaryFromMemory(&model_, &err, &warn, bytes.data(),
                                     static_cast<unsigned>(bytes.size()), baseDir);
    } else {
      // A glTF is a JSON object: anything else (an image renamed .glb) is not a scene at all.
      size_t first = 0;
      while (first < bytes.size() && std::isspace(bytes[first])) ++first;
      if (first == bytes.size() || bytes[first] != '{') fail("not a glTF or GLB file");
      ok = gltf.LoadASCIIFromString(&model_, &err, &warn,
                                    reinterpret_cast<const char*>(bytes.data()),
                                    static_cast<unsigned>(bytes.size()), baseDir);
    }
    if (!ok) fail(err.empty() ? "not a valid glTF file" : oneLine(err));
    listFiles(baseDir);
    if (!warn.empty()) {
      // tinygltf reports an unreadable image as a warning; that is checked per texture below.
      std::string w = oneLine(warn);
      if (w.find("Failed to load external 'uri' for image") == std::string::npos) this->warn(w);
    }
  }

  // Scene::files: the scene and every external buffer and image it names (percent-decoded,
  // relative to the scene's directory), so that an output is never one of them.
  void listFiles(const std::string& baseDir) {
    namespace fs = std::filesystem;
    scene_.files = {path_};
    auto add = [&](const std::string& uri) {
      if (uri.empty() || uri.rfind("data:", 0) == 0) return;
      std::string decoded;
      for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) &&
            std::isxdigit((unsigned char)uri[i + 2])) {
          decoded += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
          i += 2;
        } else {
          decoded += uri[i];
        }
      }
      scene_.files.push_back((fs::path(baseDir) / decoded).string());
    };
    for (const tinygltf::Buffer& b : model_.buffers) add(b.uri);
    for (const tinygltf::Image& i : model_.images) add(i.uri);
  }

  // tinygltf trusts the GLB chunk lengths; a truncated file must not make it read past the end.
  void checkGlbHeader(const std::vector<unsigned char>& b) const {
    auto u32 = [&](size_t at) {
      uint32_t v;
      std::memcpy(&v, b.data() + at, 4);
      return v;
    };
    if (b.size() < 20)
      fail("truncated .glb: " + std::to_string(b.size()) + " bytes, header needs 20");
    if (u32(4) != 2) fail("unsupported .glb version " + std::to_string(u32(4)));
    if (u32(8) != b.size())
      fail(std::string(u32(8) > b.size() ? "truncated" : "malformed") + " .glb: header says " +
           std::to_string(u32(8)) + " bytes, file has " + std::to_string(b.size()));
    size_t at = 12;
    int chunk = 0;
    while (at < b.size()) {
      if (at + 8 > b.size())
        fail("truncated .glb: chunk " + std::to_string(chunk) + " header cut off");
      uint64_t length = u32(at);
      if (at + 8 + length > b.size())
        fail("truncated .glb: chunk " + std::to_string(chunk) + " of " + std::to_string(length) +
             " bytes runs past the end of the file");
      if (chunk == 0 && u32(at + 4) != 0x4E4F534Au) fail("malformed .glb: first chunk is not JSON");
      at += 8 + length;
      ++chunk;
    }
  }

  void checkExtensions() {
    std::set<std::string> names(model_.extensionsUsed.begin(), model_.extensionsUsed.end());
    names.insert(model_.extensionsRequired.begin(), model_.extensionsRequired.end());
    for (const auto& m : model_.materials)
      for (const auto& [name, value] : m.extensions) names.insert(name);
    for (const std::string& name : names)
      if (!kSupportedExtensions.count(name)) warn("unsupported extension " + name + " ignored");
    // Compressed geometry cannot be ignored: its accessors have no data to fall back on.
    for (const std::string& name : model_.extensionsRequired)
      if (name == "KHR_draco_mesh_compression" || name == "EXT_meshopt_compression")
        fail("requires " + name + " (compressed geometry), which is not supported");
  }

  AccessorData accessor(int index, const std::string& what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail(what + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model_.accessors[index];
    std::string name = what + ": accessor " + std::to_string(index);
    AccessorData d;
    d.count = a.count;
    d.componentType = a.componentType;
    d.components = componentCount(a.type);
    d.normalized = a.normalized;
    size_t elementBytes = componentBytes(a.componentType) * d.components;
    if (elementBytes == 0) fail(name + " has an invalid component type or type");
    // Vertex indices are 32-bit; an accessor without a buffer view (zeros) is otherwise unbounded.
    if (d.count > 0x7fffffffu) fail(name + " count " + std::to_string(d.count) + " is too large");
    if (a.bufferView >= 0) {
      const tinygltf::BufferView& view = bufferView(a.bufferView, name);
      d.stride = view.byteStride ? view.byteStride : elementBytes;
      if (d.stride < elementBytes)
        fail(name + ": byte stride " + std::to_string(d.stride) + " is smaller than an element");
      checkRange(name, a.byteOffset, d.count, d.stride, elementBytes, a.bufferView, view);
      d.data = model_.buffers[view.buffer].data.data() + view.byteOffset + a.byteOffset;
    }
    if (a.sparse.isSparse) densify(d, a, name, elementBytes);
    return d;  // data == nullptr: no buffer view and not sparse, all zeros (spec)
  }

  const tinygltf::BufferView& bufferView(int index, const std::string& name) const {
    if (index < 0 || size_t(index) >= model_.bufferViews.size())
      fail(name + ": buffer view " + std::to_string(index) + " does not exist");
    const tinygltf::BufferView& view = model_.bufferViews[index];
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
      fail(name + ": buffer " + std::to_string(view.buffer) + " does not exist");
    const tinygltf::Buffer& buffer = model_.buffers[view.buffer];
    if (uint64_t(view.byteOffset) + view.byteLength > buffer.data.size())
      fail(name + ": buffer view " + std::to_string(index) + " (bytes " +
           std::to_string(view.byteOffset) + " + " + std::to_string(view.byteLength) +
           ") is out of range of buffer " + std::to_string(view.buffer) + " (" +
           std::to_string(buffer.data.size()) + " bytes)");
    return view;
  }

  // offset + (count - 1) * stride + element must stay inside the buffer view.
  void checkRange(const std::string& name, uint64_t offset, uint64_t count, uint64_t stride,
                  uint64_t elementBytes, int viewIndex, const tinygltf::BufferView& view) const {
    if (count == 0) return;
    uint64_t end = offset + (count - 1) * stride + elementBytes;
    if (end > view.byteLength)
      fail(name + " is out of range: offset " + std::to_string(offset) + " + " +
           std::to_string(count) + " elements x stride " + std::to_string(stride) +
           " reads past buffer view " + std::to_string(viewIndex) + " (" +
           std::to_string(view.byteLength) + " bytes)");
  }

  // Sparse accessor: a dense copy of the base (or zeros) with the listed elements replaced.
  void densify(AccessorData& d, const tinygltf::Accessor& a, const std::string& name,
               size_t elementBytes) const {
    std::string sparseName = name + " sparse";
    if (a.sparse.count < 0 || size_t(a.sparse.count) > d.count)
      fail(sparseName + " count " + std::to_string(a.sparse.count) + " is out of range");
    size_t count = size_t(a.sparse.count);
    int indexType = a.sparse.indices.componentType;
    size_t indexBytes = componentBytes(indexType);
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(sparseName + " indices are not unsigned integers");
    const tinygltf::BufferView& iv =
        bufferView(a.sparse.indices.bufferView, sparseName + " indices");
    const tinygltf::BufferView& vv = bufferView(a.sparse.values.bufferView, sparseName + " values");
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
      fail(sparseName + " has a negative byte offset");
    checkRange(sparseName + " indices", a.sparse.indices.byteOffset, count, indexBytes, indexBytes,
               a.sparse.indices.bufferView, iv);
    checkRange(sparseName + " values", a.sparse.values.byteOffset, count, elementBytes,
               elementBytes, a.sparse.values.bufferView, vv);
    auto owned = std::make_shared<std::vector<uint8_t>>(d.count * elementBytes, 0);
    if (d.data)
      for (size_t i = 0; i < d.count; ++i)
        std::memcpy(owned->data() + i * elementBytes, d.data + i * d.stride, elementBytes);
    AccessorData indices;
    indices.data =
        model_.buffers[iv.buffer].data.data() + iv.byteOffset + a.sparse.indices.byteOffset;
    indices.stride = indexBytes;
    indices.componentType = indexType;
    indices.components = 1;
    const uint8_t* values =
        model_.buffers[vv.buffer].data.data() + vv.byteOffset + a.sparse.values.byteOffset;
    for (size_t i = 0; i < count; ++i) {
      uint32_t target = indices.index(i);
      if (target >= d.count)
        fail(sparseName + " index " + std::to_string(target) + " is past the accessor count " +
             std::to_string(d.count));
      std::memcpy(owned->data() + size_t(target) * elementBytes, values + i * elementBytes,
                  elementBytes);
    }
    d.owned = owned;
    d.data = owned->data();
    d.stride = elementBytes;
  }

  // --- Materials and textures ---------------------------------------------------------------

  // KHR_texture_transform of a texture reference (nullptr: none).
  static const tinygltf::Value* transformOf(const tinygltf::ExtensionMap& extensions) {
    auto it = extensions.find("KHR_texture_transform");
    return it == extensions.end() ? nullptr : &it->second;
  }

  // Records a texture slot's KHR_texture_transform for the material being converted and
  // returns the uv slot that reads it (0: Vertex uv, 1: VertexAttributes.uv1). The transform
  // is baked into the uvs of that slot, so slots reading one set must agree; a second
  // transform of TEXCOORD_0 (SheenChair's fabric: its normal map tiles at another scale) takes
  // the uv1 slot when no slot reads TEXCOORD_1. Beyond that the first one wins, warned.
  int noteUvTransform(const tinygltf::Value* ext, int set, const std::string& what) {
    glm::mat3 m(1.0f);
    if (ext && ext->IsObject()) {
      glm::vec2 offset(0.0f), scale(1.0f);
      if (ext->Has("offset") && ext->Get("offset").IsArray() && ext->Get("offset").ArrayLen() == 2)
        offset = {ext->Get("offset").Get(0).GetNumberAsDouble(),
                  ext->Get("offset").Get(1).GetNumberAsDouble()};
      if (ext->Has("scale") && ext->Get("scale").IsArray() && ext->Get("scale").ArrayLen() == 2)
        scale = {ext->Get("scale").Get(0).GetNumberAsDouble(),
                 ext->Get("scale").Get(1).GetNumberAsDouble()};
      float r = float(number(*ext, "rotation", 0.0));
      // The extension's matrix, translation * rotation * scale; rotation is counter-clockwise
      // in uv space (v down): u' = cos u + sin v, v' = -sin u + cos v.
      glm::mat3 t(1.0f), rot(1.0f), sc(1.0f);
      t[2] = glm::vec3(offset, 1.0f);
      rot[0] = glm::vec3(std::cos(r), -std::sin(r), 0.0f);
      rot[1] = glm::vec3(std::sin(r), std::cos(r), 0.0f);
      sc[0][0] = scale.x;
      sc[1][1] = scale.y;
      m = t * rot * sc;
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k)
          if (!std::isfinite(m[c][k])) fail(what + ": KHR_texture_transform is not finite");
    }
    if (set == 1 && uv1FromUv0_) {
      warn(what + ": TEXCOORD_1 in a material whose uv1 slot carries a second transform of "
                  "TEXCOORD_0, reading that instead");
      return 1;
    }
    if (!uvTransformSet_[set]) {
      uvTransform_[set] = m;
      uvTransformSet_[set] = true;
      return set;
    }
    if (m == uvTransform_[set]) return set;
    if (set == 0 && !uvTransformSet_[1]) {
      uvTransform_[1] = m;
      uvTransformSet_[1] = true;
      uv1FromUv0_ = true;
      return 1;
    }
    if (set == 0 && uv1FromUv0_ && m == uvTransform_[1]) return 1;
    warn(what + ": texture slots with more different KHR_texture_transforms than uv slots, "
                "using the first one");
    return set;
  }

  // Our texture reference (shared/scene.h) for glTF texture `index` read with uv set
  // `texCoord` (KHR_texture_transform's texCoord overrides it).
  int texture(int index, int texCoord, const std::string& what,
              const tinygltf::Value* transform = nullptr) {
    if (index < 0) return gpu::kNoTexture;
    if (transform && transform->IsObject() && transform->Has("texCoord"))
      texCoord = wholeNumber(*transform, "texCoord", 0).value_or(-1);
    if (texCoord != 0 && texCoord != 1) {
      warn(what + ": TEXCOORD_" + std::to_string(texCoord) + " not supported, using TEXCOORD_0");
      texCoord = 0;
    }
    texCoord = noteUvTransform(transform, texCoord, what);
    int ours = textureIndex(index, what);
    if (ours < 0 || texCoord == 0) return ours;
    usesTexCoord1_ = true;
    return ours | gpu::kTextureTexCoord1;
  }

  // Our texture index for glTF texture `index`, created on first use.
  int textureIndex(int index, const std::string& what) {
    if (size_t(index) >= model_.textures.size())
      fail(what + ": texture " + std::to_string(index) + " does not exist");
    auto found = textureMap_.find(index);
    if (found != textureMap_.end()) return found->second;
    const tinygltf::Texture& t = model_.textures[index];
    if (t.source < 0) {
      // Valid glTF when an extension (KHR_texture_basisu, EXT_texture_webp) names the image.
      warn(what + ": texture " + std::to_string(index) + " has no PNG/JPEG source, ignored");
      textureMap_[index] = gpu::kNoTexture;
      return gpu::kNoTexture;
    }
    if (size_t(t.source) >= model_.images.size())
      fail(what + ": texture " + std::to_string(index) + ": image " + std::to_string(t.source) +
           " does not exist");
    const tinygltf::Image& image = model_.images[t.source];
    std::string imageName =
        "image " + std::to_string(t.source) +
        (image.uri.empty() || image.uri.rfind("data:", 0) == 0 ? std::string()
                                                               : " '" + image.uri + "'");
    if (image.image.empty() || image.width <= 0 || image.height <= 0)
      fail("missing texture image: " + imageName + " of texture " + std::to_string(index) +
           " could not be loaded");
    Texture tex;
    tex.width = uint32_t(image.width);
    tex.height = uint32_t(image.height);
    tex.name = image.name.empty() ? imageName : image.name;
    int comps = image.component, bytesPer = image.bits / 8;
    size_t texels = size_t(tex.width) * tex.height;
    if (comps < 1 || comps > 4 || (bytesPer != 1 && bytesPer != 2) ||
        image.image.size() < texels * comps * bytesPer)
      fail(imageName + ": unsupported pixel format");
    tex.texels.resize(texels);
    for (size_t i = 0; i < texels; ++i) {
      uint32_t c[4] = {0, 0, 0, 255};
      for (int k = 0; k < comps; ++k) {
        const unsigned char* p = &image.image[(i * comps + k) * bytesPer];
        // 16-bit channels (native little-endian from stb) are rounded to 8 bits.
        c[k] = bytesPer == 2 ? ((p[0] | (uint32_t(p[1]) << 8)) * 255u + 32767u) / 65535u : p[0];
      }
      if (comps == 1) c[1] = c[2] = c[0];
      if (comps == 2) {  // grey + alpha
        c[3] = c[1];
        c[1] = c[2] = c[0];
      }
      tex.texels[i] = c[0] | (c[1] << 8) | (c[2] << 16) | (c[3] << 24);
    }
    auto wrapMode = [](int gl) {
      if (gl == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return gpu::kWrapClamp;
      if (gl == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return gpu::kWrapMirror;
      return gpu::kWrapRepeat;
    };
    if (t.sampler >= 0 && size_t(t.sampler) < model_.samplers.size()) {
      const tinygltf::Sampler& s = model_.samplers[t.sampler];
      tex.wrap = wrapMode(s.wrapS) | (wrapMode(s.wrapT) << 2);
      // Magnification decides: without mipmaps, minification is the path tracer's many samples.
      if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) tex.wrap |= gpu::kTextureNearest;
    }
    int ours = int(scene_.textures.size());
    scene_.textures.push_back(std::move(tex));
    textureMap_[index] = ours;
    return ours;
  }

  // A texture reference inside an extension object: {"index": n, "texCoord": k}.
  int extensionTexture(const tinygltf::Value& ext, const char* key, const std::string& what) {
    if (!ext.IsObject() || !ext.Has(key)) return gpu::kNoTexture;
    const tinygltf::Value& info = ext.Get(key);
    const tinygltf::Value* transform = nullptr;
    if (info.IsObject() && info.Has("extensions") &&
        info.Get("extensions").Has("KHR_texture_transform"))
      transform = &info.Get("extensions").Get("KHR_texture_transform");
    const std::optional<int> index = wholeNumber(info, "index", -1);
    if (!index) fail(what + " " + key + ": the texture index is not a whole number");
    return texture(*index, wholeNumber(info, "texCoord", 0).value_or(-1), what + " " + key,
                   transform);
  }

  gpu::Material material(int index) {
    const tinygltf::Material& src = model_.materials[index];
    std::string what =
        "material " + std::to_string(index) + (src.name.empty() ? "" : " '" + src.name + "'");
    gpu::Material m = defaultMaterial();
    uvTransform_ = {glm::mat3(1.0f), glm::mat3(1.0f)};
    uvTransformSet_ = {false, false};
    usesTexCoord1_ = false;
    uv1FromUv0_ = false;
    const auto& pbr = src.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
      m.baseColor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                              pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
    m.metallic = float(pbr.metallicFactor);
    m.roughness = float(pbr.roughnessFactor);
    m.baseColorTexture = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, what,
                                 transformOf(pbr.baseColorTexture.extensions));
    m.metallicRoughnessTexture =
        texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord, what,
                transformOf(pbr.metallicRoughnessTexture.extensions));
    m.normalTexture = texture(src.normalTexture.index, src.normalTexture.texCoord, what,
                              transformOf(src.normalTexture.extensions));
    m.normalScale = float(src.normalTexture.scale);
    m.emissiveTexture = texture(src.emissiveTexture.index, src.emissiveTexture.texCoord, what,
                                transformOf(src.emissiveTexture.extensions));
    glm::vec3 emissive = toVec3(src.emissiveFactor, glm::vec3(0.0f));
    float strength = 1.0f;
    auto ext = [&](const char* name) -> const tinygltf::Value* {
      auto it = src.extensions.find(name);
      return it == src.extensions.end() ? nullptr : &it->second;
    };
    if (auto* e = ext("KHR_materials_emissive_strength"))
      strength = float(number(*e, "emissiveStrength", 1.0));
    m.emission = emissive * strength;
    if (auto* e = ext("KHR_materials_specular")) {
      m.specular = float(number(*e, "specularFactor", 1.0));
      if (e->Has("specularColorFactor")) {
        const tinygltf::Value& c = e->Get("specularColorFactor");
        if (c.IsArray() && c.ArrayLen() == 3)
          m.specularColor = glm::vec3(c.Get(0).GetNumberAsDouble(), c.Get(1).GetNumberAsDouble(),
                                      c.Get(2).GetNumberAsDouble());
      }
      m.specularTexture = extensionTexture(*e, "specularTexture", what);
      m.specularColorTexture = extensionTexture(*e, "specularColorTexture", what);
    }
    if (auto* e = ext("KHR_materials_ior")) m.ior = float(number(*e, "ior", 1.5));
    if (auto* e = ext("KHR_materials_transmission")) {
      m.transmission = float(number(*e, "transmissionFactor", 0.0));
      m.transmissionTexture = extensionTexture(*e, "transmissionTexture", what);
    }
    auto vec3Of = [&](const tinygltf::Value& e, const char* key, glm::vec3 fallback) {
      if (!e.Has(key)) return fallback;
      const tinygltf::Value& c = e.Get(key);
      if (!c.IsArray() || c.ArrayLen() != 3) fail(what + ": " + key + " is not an array of 3");
      return glm::vec3(c.Get(0).GetNumberAsDouble(), c.Get(1).GetNumberAsDouble(),
                       c.Get(2).GetNumberAsDouble());
    };
    if (auto* e = ext("KHR_materials_clearcoat")) {
      m.clearcoat = float(number(*e, "clearcoatFactor", 0.0));
      m.clearcoatRoughness = float(number(*e, "clearcoatRoughnessFactor", 0.0));
      m.clearcoatTexture = extensionTexture(*e, "clearcoatTexture", what);
      m.clearcoatRoughnessTexture = extensionTexture(*e, "clearcoatRoughnessTexture", what);
      m.clearcoatNormalTexture = extensionTexture(*e, "clearcoatNormalTexture", what);
      if (e->Has("clearcoatNormalTexture"))
        m.clearcoatNormalScale = float(number(e->Get("clearcoatNormalTexture"), "scale", 1.0));
    }
    if (auto* e = ext("KHR_materials_sheen")) {
      m.sheenColor = vec3Of(*e, "sheenColorFactor", glm::vec3(0.0f));
      m.sheenRoughness = float(number(*e, "sheenRoughnessFactor", 0.0));
      m.sheenColorTexture = extensionTexture(*e, "sheenColorTexture", what);
      m.sheenRoughnessTexture = extensionTexture(*e, "sheenRoughnessTexture", what);
    }
    if (auto* e = ext("KHR_materials_volume")) {
      // thicknessTexture is for rasterizers; a ray tracer measures the distance inside.
      m.thickness = float(number(*e, "thicknessFactor", 0.0));
      m.attenuationColor = vec3Of(*e, "attenuationColor", glm::vec3(1.0f));
      m.attenuationDistance = float(number(*e, "attenuationDistance", 0.0));
      if (m.attenuationDistance < 0.0f) fail(what + ": negative attenuationDistance");
    }
    if (auto* e = ext("KHR_materials_diffuse_transmission")) {
      m.diffuseTransmission = float(number(*e, "diffuseTransmissionFactor", 0.0));
      m.diffuseTransmissionColor = vec3Of(*e, "diffuseTransmissionColorFactor", glm::vec3(1.0f));
      m.diffuseTransmissionTexture = extensionTexture(*e, "diffuseTransmissionTexture", what);
      m.diffuseTransmissionColorTexture =
          extensionTexture(*e, "diffuseTransmissionColorTexture", what);
    }
    if (auto* e = ext("KHR_materials_anisotropy")) {
      m.anisotropyStrength = float(number(*e, "anisotropyStrength", 0.0));
      m.anisotropyRotation = float(number(*e, "anisotropyRotation", 0.0));
      m.anisotropyTexture = extensionTexture(*e, "anisotropyTexture", what);
    }
    if (auto* e = ext("KHR_materials_iridescence")) {
      m.iridescence = float(number(*e, "iridescenceFactor", 0.0));
      // "iridescenceIOR" is the draft's spelling, which early exporters wrote.
      m.iridescenceIor =
          float(number(*e, "iridescenceIor", number(*e, "iridescenceIOR", 1.3)));
      m.iridescenceThicknessMinimum = float(number(*e, "iridescenceThicknessMinimum", 100.0));
      m.iridescenceThicknessMaximum = float(number(*e, "iridescenceThicknessMaximum", 400.0));
      m.iridescenceTexture = extensionTexture(*e, "iridescenceTexture", what);
      m.iridescenceThicknessTexture = extensionTexture(*e, "iridescenceThicknessTexture", what);
      if (m.iridescenceIor <= 0.0f) fail(what + ": iridescenceIor is not positive");
      if (m.iridescenceThicknessMinimum < 0.0f || m.iridescenceThicknessMaximum < 0.0f)
        fail(what + ": negative iridescence thickness");
    }
    if (src.doubleSided) m.flags |= gpu::kMaterialDoubleSided;
    if (src.alphaMode == "MASK") {
      m.flags |= gpu::kMaterialAlphaMask;
      m.alphaCutoff = float(src.alphaCutoff);
    } else if (src.alphaMode == "BLEND") {
      m.flags |= gpu::kMaterialAlphaBlend;
    }
    const float values[] = {m.baseColor.r, m.baseColor.g,  m.baseColor.b, m.baseColor.a, m.metallic,
                            m.roughness,   m.emission.r,   m.emission.g,  m.emission.b,  m.specular,
                            m.ior,         m.transmission, m.alphaCutoff,
                            m.clearcoat,   m.clearcoatRoughness, m.sheenColor.r, m.sheenColor.g,
                            m.sheenColor.b, m.sheenRoughness, m.attenuationColor.r,
                            m.attenuationColor.g, m.attenuationColor.b, m.attenuationDistance,
                            m.diffuseTransmission, m.diffuseTransmissionColor.r,
                            m.diffuseTransmissionColor.g, m.diffuseTransmissionColor.b,
                            m.anisotropyStrength, m.anisotropyRotation, m.thickness,
                            m.iridescence, m.iridescenceIor, m.iridescenceThicknessMinimum,
                            m.iridescenceThicknessMaximum};
    for (float v : values)
      if (!std::isfinite(v)) fail(what + " has a non-finite factor");
    if (m.emission.r < 0 || m.emission.g < 0 || m.emission.b < 0)
      fail(what + " has a negative emission");
    materialUv_.push_back(uvTransform_);
    materialTexCoord1_.push_back(usesTexCoord1_);
    materialUv1FromUv0_.push_back(uv1FromUv0_);
    return m;
  }

  // --- Nodes ----------------------------------------------------------------------------------

  // The node's rest pose: its matrix, or translation, rotation (normalized), scale.
  NodePose restPose(const tinygltf::Node& node, int index) const {
    NodePose p;
    if (node.matrix.size() == 16) {
      p.hasMatrix = true;
      for (int i = 0; i < 16; ++i) glm::value_ptr(p.matrix)[i] = float(node.matrix[i]);  // column-major
      return p;
    }
    if (!node.matrix.empty()) fail("node " + std::to_string(index) + ": matrix needs 16 numbers");
    if (node.translation.size() == 3)
      p.translation = glm::vec3(node.translation[0], node.translation[1], node.translation[2]);
    if (node.rotation.size() == 4) {
      // glTF stores quaternions as (x, y, z, w); glm's constructor takes (w, x, y, z).
      glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                  float(node.rotation[2]));
      p.rotation = glm::normalize(q);
    }
    if (node.scale.size() == 3) p.scale = glm::vec3(node.scale[0], node.scale[1], node.scale[2]);
    return p;
  }

  // --- Animations -----------------------------------------------------------------------------

  // Every channel that moves a node's translation, rotation or scale, checked here so that
  // sampling needs no checks: times finite and non-decreasing, values finite and as many as
  // the keys ask. Morph-target weights are warned about and skipped, like morph targets.
  void readAnimations() {
    Animation& a = scene_.animation;
    for (size_t i = 0; i < model_.animations.size(); ++i) {
      const tinygltf::Animation& animation = model_.animations[i];
      for (size_t c = 0; c < animation.channels.size(); ++c) {
        const tinygltf::AnimationChannel& ch = animation.channels[c];
        const std::string name = "animation " + std::to_string(i) + " channel " + std::to_string(c);
        if (ch.target_node < 0) continue;  // the spec: a channel without a node is ignored
        if (size_t(ch.target_node) >= model_.nodes.size())
          fail(name + ": node " + std::to_string(ch.target_node) + " does not exist");
        AnimationChannel out;
        out.node = ch.target_node;
        if (ch.target_path == "translation") {
          out.path = TrsPath::Translation;
        } else if (ch.target_path == "rotation") {
          out.path = TrsPath::Rotation;
        } else if (ch.target_path == "scale") {
          out.path = TrsPath::Scale;
        } else if (ch.target_path == "weights") {
          warn("morph target weights not animated (morph targets not supported)");
          continue;
        } else {
          warn(name + ": target path '" + ch.target_path + "' not supported, ignored");
          continue;
        }
        if (!model_.nodes[out.node].matrix.empty()) {
          warn(name + ": node " + std::to_string(out.node) +
               " has a matrix, which glTF does not animate; ignored");
          continue;
        }
        if (ch.sampler < 0 || size_t(ch.sampler) >= animation.samplers.size())
          fail(name + ": sampler " + std::to_string(ch.sampler) + " does not exist");
        readSampler(animation.samplers[ch.sampler],
                    "animation " + std::to_string(i) + " sampler " + std::to_string(ch.sampler),
                    out);
        a.startS = a.channels.empty() ? out.times.front() : std::min(a.startS, out.times.front());
        a.endS = a.channels.empty() ? out.times.back() : std::max(a.endS, out.times.back());
        a.channels.push_back(std::move(out));
      }
    }
  }

  void readSampler(const tinygltf::AnimationSampler& s, const std::string& name,
                   AnimationChannel& out) const {
    if (s.interpolation == "LINEAR")
      out.interpolation = Interpolation::Linear;
    else if (s.interpolation == "STEP")
      out.interpolation = Interpolation::Step;
    else if (s.interpolation == "CUBICSPLINE")
      out.interpolation = Interpolation::CubicSpline;
    else
      fail(name + ": unknown interpolation '" + s.interpolation + "'");
    AccessorData in = accessor(s.input, name + " input");
    if (in.components != 1 || in.count == 0) fail(name + " input is not a list of scalar times");
    for (size_t k = 0; k < in.count; ++k) {
      const double t = in.component(k, 0);
      if (!std::isfinite(t)) fail(name + " input time " + std::to_string(k) + " is not finite");
      if (k > 0 && t < out.times.back())
        fail(name + " input times decrease at key " + std::to_string(k));
      out.times.push_back(float(t));
    }
    const int components = out.path == TrsPath::Rotation ? 4 : 3;
    const size_t perKey = out.interpolation == Interpolation::CubicSpline ? 3 : 1;
    AccessorData values = accessor(s.output, name + " output");
    if (values.components != components)
      fail(name + " output is not a " + (components == 4 ? "VEC4 (rotation)" : "VEC3"));
    if (values.count != perKey * in.count)
      fail(name + " output has " + std::to_string(values.count) + " values for " +
           std::to_string(in.count) + " keys, needs " + std::to_string(perKey * in.count));
    for (size_t k = 0; k < values.count; ++k) {
      glm::vec4 v(0.0f);
      for (int c = 0; c < components; ++c) v[c] = float(values.component(k, c));
      if (!std::isfinite(v.x + v.y + v.z + v.w))
        fail(name + " output value " + std::to_string(k) + " is not finite");
      out.values.push_back(v);
    }
  }

  void traverseScenes() {
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (size_t(sceneIndex) >= model_.scenes.size()) fail("default scene does not exist");
      roots = model_.scenes[sceneIndex].nodes;
    } else {
      // No scene: render every root node (the spec leaves this to the application).
      std::vector<bool> isChild(model_.nodes.size(), false);
      for (const auto& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && size_t(c) < isChild.size()) isChild[c] = true;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!isChild[i]) roots.push_back(int(i));
    }
    // Depth-first with an explicit stack: a deep (hostile) hierarchy must not overflow the call
    // stack. glTF node hierarchies are disjoint trees, so a node reached twice (a cycle or a
    // second parent, which could also blow up exponentially) is refused.
    std::vector<bool> reached(model_.nodes.size(), false);
    Animation& a = scene_.animation;
    std::vector<bool> animated(model_.nodes.size(), false);
    for (const AnimationChannel& c : a.channels) animated[c.node] = true;
    if (!a.empty()) {
      a.parent.assign(model_.nodes.size(), -1);
      a.rest.assign(model_.nodes.size(), NodePose{});
      a.moving.assign(model_.nodes.size(), false);
    }
    std::vector<std::pair<int, glm::mat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it)
      stack.emplace_back(*it, glm::mat4(1.0f));
    while (!stack.empty()) {
      auto [index, worldFromParent] = stack.back();
      stack.pop_back();
      if (index < 0 || size_t(index) >= model_.nodes.size())
        fail("node " + std::to_string(index) + " does not exist");
      if (reached[index])
        fail("node " + std::to_string(index) +
             " is reached twice (a cycle or two parents; glTF node hierarchies are trees)");
      reached[index] = true;
      const NodePose rest = restPose(model_.nodes[index], index);
      glm::mat4 worldFromNode = worldFromParent * rest.local();
      const std::vector<int>& children = model_.nodes[index].children;
      if (!a.empty()) {
        // Parents are visited first, so a node's moving flag is final when it is visited.
        a.order.push_back(index);
        a.rest[index] = rest;
        a.moving[index] = a.moving[index] || animated[index];
        for (int c : children)
          if (c >= 0 && size_t(c) < model_.nodes.size()) {
            if (!reached[c]) a.parent[c] = index;
            a.moving[c] = a.moving[index];
          }
      }
      visit(index, worldFromNode);
      for (auto it = children.rbegin(); it != children.rend(); ++it)
        stack.emplace_back(*it, worldFromNode);
    }
  }

  // Everything a node carries: meshes, a camera, a light.
  void visit(int index, const glm::mat4& worldFromNode) {
    const tinygltf::Node& node = model_.nodes[index];
    if (node.skin >= 0) warn("skins not supported: meshes drawn in their bind pose");
    if (!node.weights.empty()) warn("morph targets not supported: base mesh drawn");
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size())
        fail("node " + std::to_string(index) + ": mesh " + std::to_string(node.mesh) +
             " does not exist");
      const tinygltf::Mesh& mesh = model_.meshes[node.mesh];
      for (size_t p = 0; p < mesh.primitives.size(); ++p)
        primitive(mesh.primitives[p],
                  "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p),
                  worldFromNode, index);
    }
    if (node.camera >= 0) camera(node, index, worldFromNode);
    auto light = node.extensions.find("KHR_lights_punctual");
    if (light != node.extensions.end()) punctualLight(light->second, index, worldFromNode);
  }

  void primitive(const tinygltf::Primitive& prim, const std::string& what,
                 const glm::mat4& worldFromObject, int nodeIndex) {
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) {
      warn(what + ": primitive mode " + std::to_string(prim.mode) +
           " is not triangles (mode 4), skipped");
      return;
    }
    auto attr = [&](const char* name) {
      auto it = prim.attributes.find(name);
      return it == prim.attributes.end() ? -1 : it->second;
    };
    if (attr("POSITION") < 0) fail(what + " has no POSITION");
    AccessorData pos = accessor(attr("POSITION"), what + " POSITION");
    if (pos.components != 3) fail(what + " POSITION is not a VEC3");
    AccessorData nrm, uv;
    bool hasNormals = attr("NORMAL") >= 0, hasUv = attr("TEXCOORD_0") >= 0;
    if (hasNormals) {
      nrm = accessor(attr("NORMAL"), what + " NORMAL");
      if (nrm.components != 3 || nrm.count != pos.count)
        fail(what + " NORMAL does not match POSITION (type or count)");
    }
    if (hasUv) {
      uv = accessor(attr("TEXCOORD_0"), what + " TEXCOORD_0");
      if (uv.components != 2 || uv.count != pos.count)
        fail(what + " TEXCOORD_0 does not match POSITION (type or count)");
    }
    // COLOR_0 (RGB or RGBA; float, or normalized unsigned byte/short as the spec requires of
    // those types) multiplies the base colour; TEXCOORD_1 feeds the slots that ask for it.
    AccessorData color, uv1;
    bool hasColor = attr("COLOR_0") >= 0, hasUv1 = attr("TEXCOORD_1") >= 0;
    if (hasColor) {
      color = accessor(attr("COLOR_0"), what + " COLOR_0");
      if ((color.components != 3 && color.components != 4) || color.count != pos.count ||
          (color.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT &&
           color.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
           color.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT))
        fail(what + " COLOR_0 is not a VEC3/VEC4 of float, unsigned byte or unsigned short "
                    "matching POSITION");
      color.normalized = color.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT;
    }
    if (hasUv1) {
      uv1 = accessor(attr("TEXCOORD_1"), what + " TEXCOORD_1");
      if (uv1.components != 2 || uv1.count != pos.count)
        fail(what + " TEXCOORD_1 does not match POSITION (type or count)");
    }
    if (!prim.targets.empty()) warn("morph targets not supported: base mesh drawn");

    uint32_t materialIndex;
    if (prim.material < 0) {
      if (defaultMaterialIndex_ < 0) defaultMaterialIndex_ = int(model_.materials.size());
      materialIndex = uint32_t(defaultMaterialIndex_);
    } else if (size_t(prim.material) >= model_.materials.size()) {
      fail(what + ": material " + std::to_string(prim.material) + " does not exist");
    } else {
      materialIndex = uint32_t(prim.material);
    }

    // Indices: explicit (u8/u16/u32) or 0..count-1.
    std::vector<uint32_t> indices;
    if (prim.indices >= 0) {
      AccessorData idx = accessor(prim.indices, what + " indices");
      if (idx.components != 1 || (idx.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                  idx.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                  idx.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(what + " indices are not unsigned byte/short/int scalars");
      indices.resize(idx.count);
      for (size_t i = 0; i < idx.count; ++i) {
        indices[i] = idx.index(i);
        if (indices[i] >= pos.count)
          fail(what + ": index " + std::to_string(indices[i]) + " at position " +
               std::to_string(i) + " is past the vertex count " + std::to_string(pos.count));
      }
    } else {
      indices.resize(pos.count);
      for (size_t i = 0; i < pos.count; ++i) indices[i] = uint32_t(i);
    }
    if (indices.size() % 3 != 0)
      warn(what + ": index count not a multiple of 3, last " + std::to_string(indices.size() % 3) +
           " ignored");
    size_t triangleCount = indices.size() / 3;
    if (triangleCount == 0) return;
    if (scene_.vertices.size() + std::max<size_t>(pos.count, 3 * triangleCount) > 0xffffffffu)
      fail(what + ": the scene has more than 2^32 vertices");

    // Normals transform with the inverse transpose; a mirroring transform (det < 0) would
    // turn counter-clockwise front faces clockwise, so the winding is flipped to keep them.
    glm::mat3 linear(worldFromObject);
    glm::mat3 normalFromObject = glm::transpose(glm::inverse(linear));
    bool flip = glm::determinant(linear) < 0.0f;

    auto worldPosition = [&](uint32_t i) {
      glm::vec3 p = pos.vec3(i);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(what + " POSITION " + std::to_string(i) + " is not finite (NaN or Inf)");
      glm::vec3 w = glm::vec3(worldFromObject * glm::vec4(p, 1.0f));
      if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
        fail(what + " POSITION " + std::to_string(i) + " is not finite after the node transform");
      return w;
    };
    // The material's KHR_texture_transform, baked in (identity for the default material).
    std::array<glm::mat3, 2> uvFromFile =
        materialIndex < materialUv_.size() ? materialUv_[materialIndex]
                                           : std::array<glm::mat3, 2>{glm::mat3(1.0f), glm::mat3(1.0f)};
    auto uvAt = [&](uint32_t i) {
      glm::vec2 t = hasUv ? uv.vec2(i) : glm::vec2(0.0f);
      t = glm::vec2(uvFromFile[0] * glm::vec3(t, 1.0f));
      if (std::isfinite(t.x) && std::isfinite(t.y)) return t;
      warn(what + ": non-finite TEXCOORD_0 replaced by (0, 0)");
      return glm::vec2(0.0f);
    };
    bool wantsUv1 = materialIndex < materialTexCoord1_.size() && materialTexCoord1_[materialIndex];
    // The uv1 slot holding TEXCOORD_0 under the material's second transform (noteUvTransform).
    const bool uv1FromUv0 = wantsUv1 && materialUv1FromUv0_[materialIndex];
    if (wantsUv1 && !hasUv1 && !uv1FromUv0)
      warn(what + ": material asks for TEXCOORD_1, which the primitive lacks; using TEXCOORD_0");
    if (hasColor || (wantsUv1 && (hasUv1 || uv1FromUv0))) hasAttributes_ = true;
    // Vertex i's attributes, appended beside every vertex (white, uv1 = uv0 where the
    // primitive has none) so the two arrays stay parallel.
    auto appendAttributes = [&](uint32_t i, glm::vec2 uv0) {
      gpu::VertexAttributes a{};
      glm::vec4 c(1.0f);
      if (hasColor) {
        c = glm::vec4(color.vec3(i), color.components == 4 ? color.component(i, 3) : 1.0);
        if (!std::isfinite(c.r + c.g + c.b + c.a)) {
          warn(what + ": non-finite COLOR_0 replaced by white");
          c = glm::vec4(1.0f);
        }
      }
      a.colorRG = glm::packHalf2x16({c.r, c.g});
      a.colorBA = glm::packHalf2x16({c.b, c.a});
      glm::vec2 t = uv0;
      if (hasUv1 || uv1FromUv0) {
        glm::vec2 file = uv1FromUv0 ? (hasUv ? uv.vec2(i) : glm::vec2(0.0f)) : uv1.vec2(i);
        t = glm::vec2(uvFromFile[1] * glm::vec3(file, 1.0f));
        if (!std::isfinite(t.x) || !std::isfinite(t.y)) {
          warn(what + ": non-finite TEXCOORD_1 replaced by (0, 0)");
          t = glm::vec2(0.0f);
        }
      }
      a.uv1 = t;
      scene_.attributes.push_back(a);
    };

    // A primitive under an animated node keeps its object-space data to be posed again.
    const bool moving = !scene_.animation.empty() && scene_.animation.moving[nodeIndex];
    MovingPrimitive record;
    record.node = nodeIndex;
    record.firstVertex = uint32_t(scene_.vertices.size());
    record.firstTriangle = uint32_t(scene_.triangles.size());
    record.triangleCount = uint32_t(triangleCount);
    record.flatShaded = !hasNormals;
    record.mirrored = flip;
    if (hasNormals) {
      uint32_t base = uint32_t(scene_.vertices.size());
      for (uint32_t i = 0; i < pos.count; ++i) {
        glm::vec3 n = normalFromObject * nrm.vec3(i);
        float len = glm::length(n);
        gpu::Vertex v{};
        v.position = worldPosition(i);
        // A zero or broken normal falls back to the face normal in the shader (length 0).
        bool valid = len > 0.0f && std::isfinite(len);
        if (!valid) warn(what + ": zero or non-finite NORMAL replaced by the face normal");
        v.normal = valid ? n / len : glm::vec3(0.0f);
        glm::vec2 t = uvAt(i);
        v.u = t.x;
        v.v = t.y;
        scene_.vertices.push_back(v);
        appendAttributes(i, t);
        if (moving) {
          record.positions.push_back(pos.vec3(i));
          record.normals.push_back(nrm.vec3(i));
        }
      }
      for (size_t t = 0; t < triangleCount; ++t) {
        uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
        if (flip) std::swap(b, c);
        scene_.triangles.push_back({base + a, base + b, base + c, materialIndex});
      }
    } else {
      // No normals: glTF asks for flat shading, so every triangle gets its own vertices
      // carrying the face normal.
      for (size_t t = 0; t < triangleCount; ++t) {
        uint32_t id[3] = {indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]};
        if (flip) std::swap(id[1], id[2]);
        glm::vec3 p[3] = {worldPosition(id[0]), worldPosition(id[1]), worldPosition(id[2])};
        glm::vec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
        float len = glm::length(n);
        n = len > 0.0f ? n / len : glm::vec3(0.0f);
        uint32_t base = uint32_t(scene_.vertices.size());
        for (int k = 0; k < 3; ++k) {
          glm::vec2 tc = uvAt(id[k]);
          scene_.vertices.push_back({p[k], tc.x, n, tc.y});
          appendAttributes(id[k], tc);
          if (moving) record.positions.push_back(pos.vec3(id[k]));
        }
        scene_.triangles.push_back({base, base + 1, base + 2, materialIndex});
      }
    }
    if (moving) scene_.animation.primitives.push_back(std::move(record));
  }

  void camera(const tinygltf::Node& node, int nodeIndex, const glm::mat4& worldFromNode) {
    if (size_t(node.camera) >= model_.cameras.size())
      fail("node " + std::to_string(nodeIndex) + ": camera " + std::to_string(node.camera) +
           " does not exist");
    const tinygltf::Camera& c = model_.cameras[node.camera];
    if (c.type != "perspective") {
      warn("camera " + std::to_string(node.camera) + ": only perspective cameras supported, '" +
           c.type + "' skipped");
      scene_.skippedCameras.push_back({node.camera, c.type});
      return;
    }
    Camera cam;
    cam.fileIndex = node.camera;
    cam.name = !c.name.empty()      ? c.name
               : !node.name.empty() ? node.name
                                    : "camera " + std::to_string(node.camera);
    // Rigid part only: a scaled camera node must not scale the rays.
    auto rigid = rigidTransform(worldFromNode);
    if (!rigid) fail("node " + std::to_string(nodeIndex) + ": camera transform is degenerate");
    cam.worldFromCamera = *rigid;
    cam.yfov = float(c.perspective.yfov);
    cam.aspect = float(c.perspective.aspectRatio);
    if (!(cam.yfov > 0.0f && cam.yfov < 3.14159f))
      fail("camera " + std::to_string(node.camera) + ": yfov must be in (0, pi)");
    if (!(cam.aspect >= 0.0f) || !std::isfinite(cam.aspect)) cam.aspect = 0.0f;
    scene_.cameras.push_back(cam);
    if (!scene_.animation.empty()) scene_.animation.cameraNodes.push_back(nodeIndex);
  }

  void punctualLight(const tinygltf::Value& ext, int nodeIndex, const glm::mat4& worldFromNode) {
    const int index = wholeNumber(ext, "light", -1).value_or(-1);
    if (index < 0 || size_t(index) >= model_.lights.size())
      fail("node " + std::to_string(nodeIndex) + ": KHR_lights_punctual light " +
           std::to_string(index) + " does not exist");
    const tinygltf::Light& l = model_.lights[index];
    gpu::PunctualLight out{};
    glm::vec3 color = toVec3(l.color, glm::vec3(1.0f));
    out.intensity = color * float(l.intensity) / kLumensPerWatt;
    out.range = float(l.range);
    placeLight(out, worldFromNode);
    if (l.type == "point") {
      out.type = gpu::kLightPoint;
    } else if (l.type == "spot") {
      out.type = gpu::kLightSpot;
      // The spec asks 0 <= inner < outer <= pi/2; out-of-range cones are clamped into it.
      float outer = float(l.spot.outerConeAngle), inner = float(l.spot.innerConeAngle);
      if (!std::isfinite(outer) || !std::isfinite(inner))
        fail("light " + std::to_string(index) + ": spot cone angles are not finite");
      float outerOk = std::clamp(outer, 1e-4f, 1.5707964f);
      float innerOk = std::clamp(inner, 0.0f, outerOk * 0.9999f);
      if (!(outerOk == outer && innerOk == inner))
        warn("light " + std::to_string(index) +
             ": spot cone angles outside 0 <= inner < outer <= pi/2, clamped");
      out.cosInner = std::cos(innerOk);
      out.cosOuter = std::cos(outerOk);
    } else if (l.type == "directional") {
      out.type = gpu::kLightDirectional;
    } else {
      warn("light " + std::to_string(index) + ": unknown type '" + l.type + "' skipped");
      return;
    }
    if (!std::isfinite(out.intensity.r + out.intensity.g + out.intensity.b) ||
        !std::isfinite(out.position.x + out.position.y + out.position.z))
      fail("light " + std::to_string(index) + " is not finite");
    scene_.lights.push_back(out);
    if (!scene_.animation.empty()) scene_.animation.lightNodes.push_back(nodeIndex);
  }

  const std::string& path_;
  Scene& scene_;
  tinygltf::Model model_;
  std::set<std::string> warned_;
  std::map<int, int> textureMap_;
  // Per glTF material and uv set: its KHR_texture_transform; whether a slot reads TEXCOORD_1.
  std::vector<std::array<glm::mat3, 2>> materialUv_;
  std::vector<bool> materialTexCoord1_;
  std::vector<bool> materialUv1FromUv0_;
  std::array<glm::mat3, 2> uvTransform_{glm::mat3(1.0f), glm::mat3(1.0f)};  // material being
  std::array<bool, 2> uvTransformSet_{false, false};                        // converted
  bool usesTexCoord1_ = false;
  bool uv1FromUv0_ = false;
  bool hasAttributes_ = false;  // some primitive has COLOR_0 or TEXCOORD_1
  int defaultMaterialIndex_ = -1;
};

}  // namespace

void placeLight(gpu::PunctualLight& light, const glm::mat4& worldFromNode) {
  light.position = glm::vec3(worldFromNode * glm::vec4(0, 0, 0, 1));
  glm::vec3 dir = glm::mat3(worldFromNode) * glm::vec3(0, 0, -1);  // lights point down -Z
  float len = glm::length(dir);
  light.direction = len > 0.0f && std::isfinite(len) ? dir / len : glm::vec3(0, 0, -1);
}

void updateBounds(Scene& scene) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const gpu::Vertex& v : scene.vertices) {
    lo = glm::min(lo, v.position);
    hi = glm::max(hi, v.position);
  }
  scene.boundsMin = lo;
  scene.boundsMax = hi;
}

Scene loadScene(const std::string& path) {
  Scene scene;
  scene.path = path;
  try {
    Loader(path, scene).run();
  } catch (const std::bad_alloc&) {
    // Counts in a file can ask for any amount of memory; that is the file's fault.
    throw InputError(path + ": out of memory loading the scene");
  }
  return scene;
}

}  // namespace osr::scene
