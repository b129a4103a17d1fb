// Every struct of shaders/shared/*.h has one layout in C++ and in GLSL (std430 with explicit
// padding, STYLE.md 2). Three checks, each of which fails on a real divergence:
//  1. std430 by hand: each member's offsetof is where std430 puts it after the members before
//     it, sizeof is the end of the last member rounded to the struct's alignment, and a vec3
//     is followed by a scalar in its fourth lane.
//  2. The list below names every struct the shared headers declare (parsed from the files), so
//     a struct added without a layout check fails here.
//  3. The SPIR-V the device runs: for every embedded module, each struct type carrying Offset
//     decorations and named like a listed struct (OpName, OpMemberName; glslang keeps them)
//     must have the same member names and offsets, and its size, and any ArrayStride over it,
//     must equal sizeof. A struct no shader uses is covered by check 1 alone.
#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "common/test_paths.h"
#include "shaders/shader_id.h"
#include "shaders/shared/bsdf.h"
#include "shaders/shared/bvh.h"
#include "shaders/shared/bvh_build.h"
#include "shaders/shared/bvh_trace.h"
#include "shaders/shared/camera.h"
#include "shaders/shared/denoise.h"
#include "shaders/shared/film.h"
#include "shaders/shared/hemisphere.h"
#include "shaders/shared/nn.h"
#include "shaders/shared/osr.h"
#include "shaders/shared/pt.h"
#include "shaders/shared/scene.h"
#include "shaders/shared/scene_env_probe.h"
#include "shaders/shared/scene_probe.h"
#include "shaders/shared/temporal.h"
#include "shaders/shared/util_fill.h"

using namespace osr;

namespace {

// std430 size and base alignment of a member type as GLSL sees it.
template <class T>
struct Std430;
template <size_t Size, size_t Align>
struct Std430Is {
  static constexpr size_t size = Size, align = Align;
};
template <> struct Std430<float> : Std430Is<4, 4> {};
template <> struct Std430<int32_t> : Std430Is<4, 4> {};
template <> struct Std430<uint32_t> : Std430Is<4, 4> {};
template <> struct Std430<glm::vec2> : Std430Is<8, 8> {};
template <> struct Std430<glm::uvec2> : Std430Is<8, 8> {};
template <> struct Std430<glm::ivec2> : Std430Is<8, 8> {};
template <> struct Std430<glm::vec3> : Std430Is<12, 16> {};
template <> struct Std430<glm::uvec3> : Std430Is<12, 16> {};
template <> struct Std430<glm::vec4> : Std430Is<16, 16> {};
template <> struct Std430<glm::uvec4> : Std430Is<16, 16> {};
template <> struct Std430<glm::ivec4> : Std430Is<16, 16> {};
template <> struct Std430<glm::mat4> : Std430Is<64, 16> {};
// Arrays of elements whose size is a multiple of their alignment (std430 stride = size).
template <class T, size_t N>
struct Std430<T[N]> : Std430Is<N * Std430<T>::size, Std430<T>::align> {
  static_assert(Std430<T>::size % Std430<T>::align == 0, "array stride would be padded");
};
// Nested structs: their own layout is checked as a listed struct; alignment = largest member's.
template <> struct Std430<gpu::nn::View> : Std430Is<sizeof(gpu::nn::View), 4> {};
template <> struct Std430<gpu::osr::MapGrid> : Std430Is<sizeof(gpu::osr::MapGrid), 4> {};
template <> struct Std430<gpu::camera::CameraFrame> : Std430Is<sizeof(gpu::camera::CameraFrame), 16> {};
template <> struct Std430<gpu::bsdf::BsdfParams> : Std430Is<sizeof(gpu::bsdf::BsdfParams), 16> {};
template <> struct Std430<gpu::bvh_build::BuildArrays> : Std430Is<sizeof(gpu::bvh_build::BuildArrays), 8> {};
template <> struct Std430<gpu::bvh_build::DispatchArgs> : Std430Is<sizeof(gpu::bvh_build::DispatchArgs), 4> {};

struct Member {
  std::string name;
  size_t offset, size, align;
};
struct Layout {
  std::string ns, name;
  size_t size;
  std::vector<Member> members;
};

#define F(field)                                                                      \
  Member {                                                                            \
    #field, offsetof(T_, field), Std430<decltype(T_::field)>::size,                   \
        Std430<decltype(T_::field)>::align                                            \
  }
#define STRUCT(ns, S, ...)                         \
  [] {                                             \
    using T_ = gpu::ns::S;                         \
    return Layout{#ns, #S, sizeof(T_), {__VA_ARGS__}}; \
  }()

const std::vector<Layout>& layouts() {
  static const std::vector<Layout> all = {
      STRUCT(scene, Vertex, F(position), F(u), F(normal), F(v)),
      STRUCT(scene, VertexAttributes, F(colorRG), F(colorBA), F(uv1)),
      STRUCT(scene, Triangle, F(v0), F(v1), F(v2), F(material)),
      STRUCT(scene, Material, F(baseColor), F(emission), F(roughness), F(specularColor),
             F(metallic), F(specular), F(ior), F(transmission), F(alphaCutoff),
             F(baseColorTexture), F(metallicRoughnessTexture), F(normalTexture),
             F(emissiveTexture), F(transmissionTexture), F(specularTexture),
             F(specularColorTexture), F(flags), F(normalScale), F(clearcoat),
             F(clearcoatRoughness), F(clearcoatNormalScale), F(sheenColor), F(sheenRoughness),
             F(attenuationColor), F(attenuationDistance), F(diffuseTransmissionColor),
             F(diffuseTransmission), F(clearcoatTexture), F(clearcoatRoughnessTexture),
             F(clearcoatNormalTexture), F(sheenColorTexture), F(sheenRoughnessTexture),
             F(diffuseTransmissionTexture), F(diffuseTransmissionColorTexture),
             F(anisotropyTexture), F(anisotropyStrength), F(anisotropyRotation), F(thickness),
             F(iridescence), F(iridescenceIor), F(iridescenceThicknessMinimum),
             F(iridescenceThicknessMaximum), F(iridescenceTexture), F(iridescenceThicknessTexture),
             F(_pad0), F(_pad1), F(_pad2)),
      STRUCT(scene, TextureInfo, F(offset), F(width), F(height), F(wrap)),
      STRUCT(scene, EmissiveTriangle, F(triangle), F(power), F(cdf), F(area)),
      STRUCT(scene, PunctualLight, F(position), F(type), F(direction), F(range), F(intensity),
             F(cosInner), F(cosOuter), F(_pad0), F(_pad1), F(_pad2)),
      STRUCT(scene, SceneInfo, F(triangleCount), F(emissiveCount), F(lightCount), F(envWidth),
             F(envHeight), F(envScale), F(emissivePower), F(vertexAttributes), F(boundsMin),
             F(boundsMax)),
      STRUCT(bvh, BvhNode, F(aMin), F(a), F(aMax), F(b), F(bMin), F(_pad0), F(bMax), F(_pad1)),
      STRUCT(bvh, BvhTraversalNode, F(frame), F(boxes)),
      STRUCT(bvh, BvhLeafTriangle, F(v0), F(v1), F(v2)),
      STRUCT(bvh_build, BvhBuildNode, F(lo), F(cost), F(hi), F(triangleCount), F(left),
             F(right), F(parent), F(flags)),
      STRUCT(bvh_build, BvhBuildInfo, F(centroidMin), F(centroidMax), F(leafCounter), F(_pad0),
             F(_pad1), F(_pad2)),
      STRUCT(bvh_build, BuildArrays, F(triangles), F(vertices), F(prims), F(interior), F(leaves),
             F(nodes), F(leafTriangles), F(traversalNodes)),
      STRUCT(bvh_build, BuildPush, F(triangleCount), F(param), F(param2), F(_pad0), F(arrays)),
      STRUCT(bvh_build, LevelList, F(count), F(offset), F(_pad0), F(_pad1)),
      STRUCT(bvh_build, DispatchArgs, F(x), F(y), F(z)),
      STRUCT(bvh_build, PlocState, F(count), F(iterations), F(pairs), F(args0), F(args1), F(pairArgs), F(root),
             F(clusterParity), F(tailClusters)),
      STRUCT(bvh_trace, TraceRay, F(origin), F(tMin), F(dir), F(tMax)),
      STRUCT(bvh_trace, TraceHit, F(t), F(triangle), F(barycentrics)),
      STRUCT(bvh_trace, Push, F(rayCount), F(mode), F(raysPerLane), F(_pad0)),
      STRUCT(nn, View, F(cTotal), F(c0), F(_pad0), F(_pad1)),
      STRUCT(nn, ConvPush, F(src), F(dst), F(maps), F(cin), F(cout), F(coutPadded), F(height),
             F(width), F(tileCount), F(tileGroupsY), F(validHeight), F(validWidth), F(_pad0), F(_pad1)),
      STRUCT(nn, PoolPush, F(src), F(dst), F(maps), F(channels), F(inHeight), F(inWidth),
             F(outHeight), F(outWidth), F(validInHeight), F(validInWidth), F(pairCount), F(groupsX),
             F(_pad0), F(_pad1)),
      STRUCT(denoise, ExposureSums, F(logSum), F(count), F(exposure), F(_pad0)),
      STRUCT(denoise, DenoisePush, F(width), F(height), F(paddedWidth), F(paddedHeight), F(tileX),
             F(tileY), F(tileWidth), F(tileHeight), F(coreX0), F(coreY0), F(coreX1), F(coreY1),
             F(step), F(sigmaLuminance), F(sigmaNormal), F(sigmaDepth), F(samples), F(_pad0), F(_pad1),
             F(_pad2)),
      STRUCT(film, FilmPixel, F(combined), F(direct), F(indirect), F(albedo), F(normal), F(depth)),
      STRUCT(camera, CameraFrame, F(cameraRight), F(cameraUp), F(cameraBack), F(cameraOrigin),
             F(width), F(height), F(seed), F(pixelFilter), F(tanHalfFovY), F(aspect), F(_pad1),
             F(_pad2), F(imageWidth), F(imageHeight), F(originX), F(originY)),
      STRUCT(hemi, HemiProbeCase, F(square), F(direction), F(normal), F(toDirection),
             F(toSquare), F(frameT), F(frameB)),
      STRUCT(osr, GBufferPixel, F(position), F(normal), F(geomNormal), F(wo), F(throughput),
             F(bsdf)),
      STRUCT(osr, AccumPixel, F(direct), F(indirect), F(residual), F(residualSq), F(albedo),
             F(normal), F(depth), F(compositeSq), F(tracedSq), F(mirroredSq)),
      STRUCT(osr, MapPoint, F(position), F(normal), F(pixel)),
      STRUCT(osr, MapProjection, F(mean), F(sh), F(rowLuminance)),
      STRUCT(osr, MapStats, F(meanRadiance), F(meanDistance)),
      STRUCT(osr, MapGrid, F(radius), F(cellsX), F(cellsY), F(seed)),
      STRUCT(osr, GBufferPush, F(pass), F(pixelOffset), F(pixelCount), F(cameraRays),
             F(directWeight)),
      STRUCT(osr, DirectPush, F(pass), F(pixelOffset), F(pixelCount), F(lightSamples)),
      STRUCT(osr, MapsPush, F(grid), F(pass), F(mapOffset), F(mapCount), F(pathsPerTexel),
             F(gbufferWindowOffset)),
      STRUCT(osr, MapNormalizePush, F(mapCount)),
      STRUCT(osr, MapDenoisePush, F(mapOffset), F(mapCount)),
      STRUCT(osr, MapCacheEntry, F(position), F(normal), F(state)),
      STRUCT(osr, MapCacheRef, F(action), F(slot), F(key), F(passes)),
      STRUCT(osr, MapCachePush, F(grid), F(mapOffset), F(mapCount), F(gbufferWindowOffset),
             F(sets), F(generation), F(clock), F(mapPass), F(phase), F(cellScale), F(maturePasses),
             F(_pad1), F(_pad2)),
      STRUCT(osr, MapProjectPush, F(mapOffset), F(mapCount)),
      STRUCT(osr, CompositePush, F(grid), F(pass), F(pixelOffset), F(pixelCount),
             F(cleanMapOffset), F(glossySamples), F(passWeight), F(momentWeight)),
      STRUCT(osr, ResidualPush, F(grid), F(pass), F(pixelOffset), F(pixelCount),
             F(cleanMapOffset), F(pathsPerPixel), F(passWeight), F(guideShare)),
      STRUCT(osr, ResolvePush, F(pixelOffset), F(pixelCount), F(residualBlend), F(residualNoiseWeight)),
      STRUCT(pt, Push, F(pixelOffset), F(pixelCount), F(sampleIndex), F(sampleCount)),
      STRUCT(temporal, TemporalCameras, F(current), F(previous)),
      STRUCT(temporal, TemporalPush, F(width), F(height), F(samples), F(maxHistory), F(rejectSigma),
             F(_pad0), F(_pad1), F(_pad2)),
      STRUCT(bsdf, BsdfParams, F(baseColor), F(metallic), F(specularColor), F(roughness),
             F(specular), F(eta), F(transmission), F(_pad0), F(clearcoatNormal), F(clearcoat),
             F(sheenColor), F(sheenRoughness), F(diffuseTransmissionColor),
             F(diffuseTransmission), F(anisotropyDirection), F(anisotropy),
             F(clearcoatRoughness), F(iridescence), F(iridescenceIor),
             F(iridescenceThickness), F(_pad1)),
      STRUCT(bsdf, ProbeCase, F(params), F(wo)),
      STRUCT(bsdf, ProbePush, F(mode), F(caseCount), F(thetaCount), F(phiCount),
             F(samplesPerCase), F(seed), F(_pad0), F(_pad1)),
      STRUCT(bsdf, ProbeOut, F(value), F(pdf), F(evalValue), F(evalPdf), F(wi), F(flags)),
      STRUCT(scene_probe, Query, F(triangle), F(b1), F(b2), F(_pad0)),
      STRUCT(scene_probe, Result, F(position), F(material), F(geometricNormal), F(alphaCutout),
             F(shadingNormal), F(alpha), F(baseColor), F(metallic), F(emission), F(roughness),
             F(specularColor), F(specular), F(uv), F(ior), F(transmission), F(doubleSided),
             F(_pad0), F(_pad1), F(_pad2)),
      STRUCT(scene_probe, Push, F(count)),
      STRUCT(scene_env_probe, Query, F(direction), F(_pad0), F(u), F(_pad1)),
      STRUCT(scene_env_probe, Result, F(radiance), F(pdf), F(sampledDirection), F(sampledPdf),
             F(sampledRadiance), F(_pad0)),
      STRUCT(scene_env_probe, Push, F(count)),
      STRUCT(util_fill, Push, F(count), F(value)),
  };
  return all;
}
#undef F
#undef STRUCT

size_t roundUp(size_t x, size_t a) { return (x + a - 1) / a * a; }

TEST(SharedLayout, StructsFollowStd430) {
  for (const Layout& s : layouts()) {
    SCOPED_TRACE(s.ns + "::" + s.name);
    size_t end = 0, align = 4;
    for (size_t i = 0; i < s.members.size(); ++i) {
      const Member& m = s.members[i];
      EXPECT_EQ(m.offset, roundUp(end, m.align)) << "member " << m.name;
      if (m.size == 12 && m.align == 16) {  // vec3: a 4-byte scalar must fill its fourth lane
        EXPECT_TRUE(i + 1 < s.members.size() && s.members[i + 1].size == 4 &&
                    s.members[i + 1].offset == m.offset + 12)
            << "vec3 member " << m.name << " not followed by a scalar";
      }
      end = m.offset + m.size;
      align = std::max(align, m.align);
    }
    EXPECT_EQ(s.size, roundUp(end, align)) << "sizeof (padding must be written out)";
  }
}

TEST(SharedLayout, EveryStructOfTheSharedHeadersIsListed) {
  std::set<std::string> listed, declared;
  for (const Layout& s : layouts()) listed.insert(s.ns + "::" + s.name);
  const std::regex nsRe(R"(OSR_NAMESPACE_BEGIN\((\w+)\))"), structRe(R"(^struct (\w+)\b)");
  const std::filesystem::path dir = test::sourcePath("shaders/shared");
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".h") continue;
    std::ifstream in(entry.path());
    std::string line, ns;
    std::smatch m;
    while (std::getline(in, line)) {
      if (std::regex_search(line, m, nsRe)) ns = m[1];
      if (std::regex_search(line, m, structRe)) declared.insert(ns + "::" + std::string(m[1]));
    }
  }
  ASSERT_FALSE(declared.empty()) << dir;
  for (const std::string& d : declared)
    EXPECT_TRUE(listed.count(d)) << d << " is declared in shaders/shared but has no layout check";
  for (const std::string& l : listed)
    EXPECT_TRUE(declared.count(l)) << l << " is listed but no longer declared";
}

// ---- SPIR-V ------------------------------------------------------------------------------

struct SpirvStruct {
  std::string name;
  std::vector<uint32_t> memberTypes;
  std::map<uint32_t, std::string> memberNames;
  std::map<uint32_t, uint32_t> offsets;
};

struct SpirvModule {
  std::map<uint32_t, std::string> names;
  std::map<uint32_t, SpirvStruct> structs;
  std::map<uint32_t, std::vector<uint32_t>> types;  // id -> opcode, operands after the id
  std::map<uint32_t, uint32_t> constants;           // 32-bit OpConstant values
  std::map<uint32_t, uint32_t> arrayStrides;

  explicit SpirvModule(const shaders::Module& m) {
    const uint32_t* w = m.code;
    EXPECT_EQ(w[0], 0x07230203u) << m.name;
    auto str = [](const uint32_t* p) { return std::string(reinterpret_cast<const char*>(p)); };
    std::map<std::pair<uint32_t, uint32_t>, std::string> memberNames;
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> offsets;
    for (size_t i = 5; i < m.words;) {
      const uint32_t op = w[i] & 0xffffu, n = w[i] >> 16;
      if (n == 0) break;
      const uint32_t* a = w + i + 1;
      switch (op) {
        case 5: names[a[0]] = str(a + 1); break;                             // OpName
        case 6: memberNames[{a[0], a[1]}] = str(a + 2); break;                // OpMemberName
        case 71: if (a[1] == 6) arrayStrides[a[0]] = a[2]; break;            // ArrayStride
        case 72: if (a[2] == 35) offsets[{a[0], a[1]}] = a[3]; break;        // Offset
        case 43: if (n == 4) constants[a[1]] = a[2]; break;                  // OpConstant
        case 20: case 21: case 22: case 23: case 24: case 28: case 29: case 30:  // types
          types[a[0]] = {op};
          types[a[0]].insert(types[a[0]].end(), a + 1, a + n - 1);
          break;
        default: break;
      }
      i += n;
    }
    for (const auto& [id, t] : types) {
      if (t[0] != 30) continue;  // OpTypeStruct
      SpirvStruct s;
      s.name = names.count(id) ? names[id] : "";
      s.memberTypes.assign(t.begin() + 1, t.end());
      for (uint32_t k = 0; k < s.memberTypes.size(); ++k) {
        if (memberNames.count({id, k})) s.memberNames[k] = memberNames[{id, k}];
        if (offsets.count({id, k})) s.offsets[k] = offsets[{id, k}];
      }
      structs[id] = s;
    }
  }

  // Bytes a value of `type` occupies in an explicitly laid out block (std430 here).
  size_t size(uint32_t type) const {
    const std::vector<uint32_t>& t = types.at(type);
    switch (t[0]) {
      case 20: return 4;                                   // bool (4 bytes in a block)
      case 21: case 22: return t[1] / 8;                   // int, float
      case 23: return t[2] * size(t[1]);                   // vector
      case 24: return t[2] * roundUp(size(t[1]), 16);      // matrix of vec4-aligned columns
      case 28: return constants.at(t[2]) * arrayStrides.at(type);
      case 29: return 0;                                   // runtime array
      case 30: {
        const SpirvStruct& s = structs.at(type);
        size_t end = 0;
        for (const auto& [k, off] : s.offsets) end = std::max(end, off + size(s.memberTypes[k]));
        return end;
      }
    }
    return 0;
  }
};

// The shared-header namespace of each pass, for names two headers declare (Push, Query, ...).
std::string passNamespace(const std::string& module) {
  static const std::vector<std::pair<std::string, std::string>> prefixes = {
      {"bvh_trace_rays", "bvh_trace"}, {"bvh_", "bvh_build"},     {"nn_", "nn"},
      {"pt_bsdf_probe", "bsdf"},       {"pt_", "pt"},             {"scene_env_probe", "scene_env_probe"},
      {"scene_probe", "scene_probe"},  {"util_fill", "util_fill"},
      {"osr_hemisphere_probe", "hemi"}, {"osr_", "osr"}};
  for (const auto& [prefix, ns] : prefixes)
    if (module.rfind(prefix, 0) == 0) return ns;
  return "";
}

const Layout* findLayout(const std::string& module, const std::string& name) {
  std::vector<const Layout*> byName;
  for (const Layout& l : layouts())
    if (l.name == name) byName.push_back(&l);
  if (byName.size() <= 1) return byName.empty() ? nullptr : byName[0];
  for (const Layout* l : byName)
    if (l->ns == passNamespace(module)) return l;
  ADD_FAILURE() << module << ": struct " << name
                << " is declared by several shared headers and the pass's own header is unknown";
  return nullptr;
}

TEST(SharedLayout, ShadersUseTheCppLayout) {
  std::set<std::string> seen;
  size_t checkedStructs = 0;
  for (size_t id = 0; id < shaders::kModuleCount; ++id) {
    const shaders::Module& mod = shaders::module(shaders::Id(id));
    SCOPED_TRACE(mod.name);
    SpirvModule spv(mod);
    ASSERT_FALSE(spv.names.empty()) << "no OpName: modules compiled without debug names";
    for (const auto& [typeId, s] : spv.structs) {
      if (s.offsets.empty()) continue;  // a function-local copy: no explicit layout
      const Layout* l = findLayout(mod.name, s.name);
      if (!l) continue;  // a block (SceneVertices, PushBlock, ...), not a shared struct
      SCOPED_TRACE(l->ns + "::" + l->name);
      ++checkedStructs;
      seen.insert(l->ns + "::" + l->name);
      EXPECT_EQ(s.memberTypes.size(), l->members.size()) << "member count";
      for (const auto& [k, off] : s.offsets) {
        const std::string& name = s.memberNames.count(k) ? s.memberNames.at(k) : "";
        auto it = std::find_if(l->members.begin(), l->members.end(),
                               [&](const Member& m) { return m.name == name; });
        if (it == l->members.end()) {
          ADD_FAILURE() << "GLSL member '" << name << "' has no C++ twin";
          continue;
        }
        EXPECT_EQ(off, it->offset) << "offset of " << name;
        EXPECT_EQ(spv.size(s.memberTypes[k]), it->size) << "size of " << name;
      }
      EXPECT_EQ(spv.size(typeId), l->size) << "size";
    }
    // Arrays of shared structs (buffer contents) must step by sizeof.
    for (const auto& [typeId, t] : spv.types) {
      if ((t[0] != 28 && t[0] != 29) || !spv.arrayStrides.count(typeId)) continue;
      auto s = spv.structs.find(t[1]);
      if (s == spv.structs.end()) continue;
      if (const Layout* l = findLayout(mod.name, s->second.name)) {
        EXPECT_EQ(spv.arrayStrides.at(typeId), l->size) << "array stride of " << l->name;
      }
    }
  }
  EXPECT_GT(checkedStructs, 0u);
  std::string unused;
  for (const Layout& l : layouts())
    if (!seen.count(l.ns + "::" + l.name)) unused += " " + l.ns + "::" + l.name;
  std::printf("%zu struct layouts checked in SPIR-V; shared structs no shader lays out (std430 "
              "by hand only):%s\n",
              checkedStructs, unused.empty() ? " none" : unused.c_str());
}

}  // namespace
