// Scene buffers and accessors for every pass that shades or tests alpha.
//
// Usage: #define OSR_SCENE_BINDING <first slot> before including; the scene then occupies
// slots OSR_SCENE_BINDING + 0 .. + kSceneBindingCount - 1 in the order of the kSceneBinding*
// constants of shared/scene.h, which is the order osr::scene::GpuScene::bindings() returns.
// C++ twins of every function here live in src/scene/surface.h and are tested against this
// file by tests/scene_gpu/test_scene_probe.cpp.
#ifndef OSR_LIB_SCENE_GLSL
#define OSR_LIB_SCENE_GLSL

#ifndef OSR_SCENE_BINDING
#error "#define OSR_SCENE_BINDING (first binding slot of the scene buffers) before including lib/scene.glsl"
#endif

#include "shared/scene.h"

#ifndef OSR_SCENE_FEATURES
#define OSR_SCENE_FEATURES kSceneFeatureAll
#endif
// False only where the includer's OSR_SCENE_FEATURES lacks `feature` (see shared/scene.h).
bool sceneHas(uint feature) { return (OSR_SCENE_FEATURES & feature) != 0u; }

layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingVertices) readonly buffer SceneVertices {
  Vertex gVertices[];
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingTriangles) readonly buffer SceneTriangles {
  Triangle gTriangles[];
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingMaterials) readonly buffer SceneMaterials {
  Material gMaterials[];
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingTextureInfos) readonly buffer SceneTextureInfos {
  TextureInfo gTextureInfos[];
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingTexels) readonly buffer SceneTexels {
  uint gTexels[];
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingLights) readonly buffer SceneLights {
  PunctualLight gLights[];
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingEmissive) readonly buffer SceneEmissive {
  EmissiveTriangle gEmissive[];
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingInfo) readonly buffer SceneInfoBlock {
  SceneInfo gSceneInfo;
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingEnvironment) readonly buffer SceneEnvironment {
  vec4 gEnvironment[];  // envWidth x envHeight linear RGB radiance, row 0 = top (+Y)
};
layout(std430, binding = OSR_SCENE_BINDING + kSceneBindingEnvironmentCdf) readonly buffer SceneEnvironmentCdf {
  // [0, envHeight): inclusive marginal CDF over rows; then per row y at envHeight + y *
  // envWidth: inclusive conditional CDF over its columns. Both end in exactly 1.
  float gEnvironmentCdf[];
};

const float kScenePi = 3.14159265358979;

// ---- Element reads: texel fetch where the pass binds the texel views ------------------------
#ifdef OSR_SCENE_TEXEL_BINDING
layout(binding = OSR_SCENE_TEXEL_BINDING + kSceneTexelBindingVertices)
uniform usamplerBuffer gVertexTexels;
layout(binding = OSR_SCENE_TEXEL_BINDING + kSceneTexelBindingTriangles)
uniform usamplerBuffer gTriangleTexels;
layout(binding = OSR_SCENE_TEXEL_BINDING + kSceneTexelBindingMaterials)
uniform usamplerBuffer gMaterialTexels;
layout(constant_id = kSceneSpecTexelFetch) const bool kSceneTexelFetch = true;
#else
const bool kSceneTexelFetch = false;
#endif

Vertex sceneVertex(uint i) {
#ifdef OSR_SCENE_TEXEL_BINDING
  if (kSceneTexelFetch) {
    uvec4 a = texelFetch(gVertexTexels, int(2u * i));
    uvec4 b = texelFetch(gVertexTexels, int(2u * i + 1u));
    Vertex v;
    v.position = uintBitsToFloat(a.xyz);
    v.u = uintBitsToFloat(a.w);
    v.normal = uintBitsToFloat(b.xyz);
    v.v = uintBitsToFloat(b.w);
    return v;
  }
#endif
  return gVertices[i];
}

Triangle sceneTriangle(uint i) {
#ifdef OSR_SCENE_TEXEL_BINDING
  if (kSceneTexelFetch) {
    uvec4 a = texelFetch(gTriangleTexels, int(i));
    return Triangle(a.x, a.y, a.z, a.w);
  }
#endif
  return gTriangles[i];
}

Material sceneMaterial(uint i) {
#ifdef OSR_SCENE_TEXEL_BINDING
  if (kSceneTexelFetch) {
    // Layout from shared/scene.h: the field at word w is lane w % 4 of texel w / 4.
    int base = int(kMaterialTexels * i);
    uvec4 t[kMaterialTexels];
    for (int k = 0; k < int(kMaterialBaseTexels); ++k) t[k] = texelFetch(gMaterialTexels, base + k);
    // The layered lobes' words: fetched only where some material has one (evaluateMaterial
    // reads none of them otherwise).
    bool layers = sceneHas(kSceneFeatureLayers);
    for (int k = int(kMaterialBaseTexels); k < int(kMaterialTexels); ++k)
      t[k] = layers ? texelFetch(gMaterialTexels, base + k) : uvec4(0u);
#define OSR_MW(w) t[(w) / 4u][(w) % 4u]
#define OSR_MW3(w) uvec3(OSR_MW(w), OSR_MW((w) + 1u), OSR_MW((w) + 2u))
    Material m;
    m.baseColor = uintBitsToFloat(t[kMaterialWordBaseColor / 4u]);  // vec4: a whole texel
    m.emission = uintBitsToFloat(OSR_MW3(kMaterialWordEmission));
    m.roughness = uintBitsToFloat(OSR_MW(kMaterialWordRoughness));
    m.specularColor = uintBitsToFloat(OSR_MW3(kMaterialWordSpecularColor));
    m.metallic = uintBitsToFloat(OSR_MW(kMaterialWordMetallic));
    m.specular = uintBitsToFloat(OSR_MW(kMaterialWordSpecular));
    m.ior = uintBitsToFloat(OSR_MW(kMaterialWordIor));
    m.transmission = uintBitsToFloat(OSR_MW(kMaterialWordTransmission));
    m.alphaCutoff = uintBitsToFloat(OSR_MW(kMaterialWordAlphaCutoff));
    m.baseColorTexture = int(OSR_MW(kMaterialWordBaseColorTexture));
    m.metallicRoughnessTexture = int(OSR_MW(kMaterialWordMetallicRoughnessTexture));
    m.normalTexture = int(OSR_MW(kMaterialWordNormalTexture));
    m.emissiveTexture = int(OSR_MW(kMaterialWordEmissiveTexture));
    m.transmissionTexture = int(OSR_MW(kMaterialWordTransmissionTexture));
    m.specularTexture = int(OSR_MW(kMaterialWordSpecularTexture));
    m.specularColorTexture = int(OSR_MW(kMaterialWordSpecularColorTexture));
    m.flags = OSR_MW(kMaterialWordFlags);
    m.normalScale = uintBitsToFloat(OSR_MW(kMaterialWordNormalScale));
    m.clearcoat = uintBitsToFloat(OSR_MW(kMaterialWordClearcoat));
    m.clearcoatRoughness = uintBitsToFloat(OSR_MW(kMaterialWordClearcoatRoughness));
    m.clearcoatNormalScale = uintBitsToFloat(OSR_MW(kMaterialWordClearcoatNormalScale));
    m.sheenColor = uintBitsToFloat(OSR_MW3(kMaterialWordSheenColor));
    m.sheenRoughness = uintBitsToFloat(OSR_MW(kMaterialWordSheenRoughness));
    m.attenuationColor = uintBitsToFloat(OSR_MW3(kMaterialWordAttenuationColor));
    m.attenuationDistance = uintBitsToFloat(OSR_MW(kMaterialWordAttenuationDistance));
    m.diffuseTransmissionColor = uintBitsToFloat(OSR_MW3(kMaterialWordDiffuseTransmissionColor));
    m.diffuseTransmission = uintBitsToFloat(OSR_MW(kMaterialWordDiffuseTransmission));
    m.clearcoatTexture = int(OSR_MW(kMaterialWordClearcoatTexture));
    m.clearcoatRoughnessTexture = int(OSR_MW(kMaterialWordClearcoatRoughnessTexture));
    m.clearcoatNormalTexture = int(OSR_MW(kMaterialWordClearcoatNormalTexture));
    m.sheenColorTexture = int(OSR_MW(kMaterialWordSheenColorTexture));
    m.sheenRoughnessTexture = int(OSR_MW(kMaterialWordSheenRoughnessTexture));
    m.diffuseTransmissionTexture = int(OSR_MW(kMaterialWordDiffuseTransmissionTexture));
    m.diffuseTransmissionColorTexture = int(OSR_MW(kMaterialWordDiffuseTransmissionColorTexture));
    m.anisotropyTexture = int(OSR_MW(kMaterialWordAnisotropyTexture));
    m.anisotropyStrength = uintBitsToFloat(OSR_MW(kMaterialWordAnisotropyStrength));
    m.anisotropyRotation = uintBitsToFloat(OSR_MW(kMaterialWordAnisotropyRotation));
    m.thickness = uintBitsToFloat(OSR_MW(kMaterialWordThickness));
    m.iridescence = uintBitsToFloat(OSR_MW(kMaterialWordIridescence));
    m.iridescenceIor = uintBitsToFloat(OSR_MW(kMaterialWordIridescenceIor));
    m.iridescenceThicknessMinimum =
        uintBitsToFloat(OSR_MW(kMaterialWordIridescenceThicknessMinimum));
    m.iridescenceThicknessMaximum =
        uintBitsToFloat(OSR_MW(kMaterialWordIridescenceThicknessMaximum));
    m.iridescenceTexture = int(OSR_MW(kMaterialWordIridescenceTexture));
    m.iridescenceThicknessTexture = int(OSR_MW(kMaterialWordIridescenceThicknessTexture));
#undef OSR_MW3
#undef OSR_MW
    m._pad0 = 0.0;
    m._pad1 = 0.0;
    m._pad2 = 0.0;
    return m;
  }
#endif
  return gMaterials[i];
}

// ---- Textures -------------------------------------------------------------------------------

vec3 srgbToLinear(vec3 c) {
  vec3 lo = c / 12.92;
  vec3 hi = pow((c + 0.055) / 1.055, vec3(2.4));
  return mix(hi, lo, lessThanEqual(c, vec3(0.04045)));
}

// i mod n in [0, n) for n > 0 and any i. Not `%`: GLSL leaves it undefined for negative
// operands. The float quotient may be off by one period; the two corrections fix that.
int scenePositiveMod(int i, int n) {
  int m = i - n * int(floor(float(i) / float(n)));
  if (m < 0) m += n;
  if (m >= n) m -= n;
  return m;
}

// Integer texel coordinate i wrapped into [0, size) by a glTF wrap mode.
int sceneWrap(int i, int size, uint mode) {
  if (mode == kWrapClamp) return clamp(i, 0, size - 1);
  if (mode == kWrapMirror) {
    int m = scenePositiveMod(i, 2 * size);
    return clamp(m < size ? m : 2 * size - 1 - m, 0, size - 1);
  }
  return clamp(scenePositiveMod(i, size), 0, size - 1);
}

vec4 sceneTexel(TextureInfo info, int x, int y) {
  return unpackUnorm4x8(gTexels[info.offset + uint(y) * info.width + uint(x)]);
}

// Bilinear (or nearest, kTextureNearest) lookup of texture reference `texture` (shared/scene.h:
// an index, | kTextureTexCoord1 for the second uv set) with the texture's wrap modes; uvs.xy
// is TEXCOORD_0, uvs.zw TEXCOORD_1 (sceneTexCoords). Texel centres at (i + 0.5) / size, uv
// (0,0) is the first texel of row 0 (glTF). Raw RGBA in [0, 1]: the caller decodes sRGB.
// kNoTexture returns white, so `factor * sampleTexture(...)` needs no branch.
vec4 sampleTexture(int texture, vec4 uvs) {
  if (!sceneHas(kSceneFeatureTextures) || texture < 0) return vec4(1.0);
  vec2 uv = (texture & kTextureTexCoord1) != 0 ? uvs.zw : uvs.xy;
  TextureInfo info = gTextureInfos[texture & kTextureIndexMask];
  int w = int(info.width), h = int(info.height);
  // Clamped so that the conversions to int below are defined (uv far outside [0, 1] or NaN
  // still gives some texel of the texture, never a read outside it).
  vec2 st = clamp(uv * vec2(w, h) - 0.5, vec2(-1e9), vec2(1e9));
  // Nearest: the texel containing uv, i.e. the bilinear lookup at a texel centre.
  if ((info.wrap & kTextureNearest) != 0u) st = floor(st + 0.5);
  vec2 base = floor(st);
  vec2 f = st - base;
  int x0 = int(base.x), y0 = int(base.y);
  uint wrapS = info.wrap & 3u, wrapT = (info.wrap >> 2) & 3u;
  int xa = sceneWrap(x0, w, wrapS), xb = sceneWrap(x0 + 1, w, wrapS);
  int ya = sceneWrap(y0, h, wrapT), yb = sceneWrap(y0 + 1, h, wrapT);
  vec4 top = mix(sceneTexel(info, xa, ya), sceneTexel(info, xb, ya), f.x);
  vec4 bottom = mix(sceneTexel(info, xa, yb), sceneTexel(info, xb, yb), f.x);
  return mix(top, bottom, f.y);
}

// ---- Surfaces -------------------------------------------------------------------------------

// A material evaluated at a surface point: textures applied, colours linear.
struct SurfaceMaterial {
  vec3 baseColor;
  float alpha;
  vec3 emission;  // radiance, emitted from the front side (and the back where doubleSided)
  float metallic;
  vec3 specularColor;
  float roughness;  // perceptual
  float specular;
  float ior;
  float transmission;
  bool doubleSided;
  // Layered lobes (zero where the scene has none: kSceneFeatureLayers).
  float clearcoat;
  float clearcoatRoughness;  // perceptual
  vec3 sheenColor;
  float sheenRoughness;      // perceptual
  vec3 diffuseTransmissionColor;
  float diffuseTransmission;
  vec3 absorption;           // KHR_materials_volume sigma_a = -log(attenuationColor) / distance, per metre
  float anisotropy;          // strength
  vec2 anisotropyDirection;  // unit, in the uv tangent frame (tangent, bitangent)
  float iridescence;           // KHR_materials_iridescence: factor x texture R (0: no film)
  float iridescenceIor;
  float iridescenceThickness;  // nanometres
};

struct SurfaceSample {
  vec3 position;         // world space
  vec3 geometricNormal;  // unit, from the winding: normalize(cross(p1 - p0, p2 - p0))
  vec3 shadingNormal;    // unit: interpolated vertex normal, then the normal map if any
  vec4 uv;               // TEXCOORD_0 (xy) and TEXCOORD_1 (zw), see sceneTexCoords
  uint material;  // index into gMaterials
  SurfaceMaterial m;
  vec3 clearcoatNormal;  // unit: the coat's normal (interpolated normal, then its own map)
  vec3 anisotropyTangent;  // unit world direction of increased roughness (0: isotropic)
};

// Vertex v's VertexAttributes, stored after the texels (SceneInfo.vertexAttributes).
VertexAttributes sceneVertexAttribute(uint v) {
  uint w = gSceneInfo.vertexAttributes + 4u * v;
  VertexAttributes a;
  a.colorRG = gTexels[w];
  a.colorBA = gTexels[w + 1u];
  a.uv1 = uintBitsToFloat(uvec2(gTexels[w + 2u], gTexels[w + 3u]));
  return a;
}

vec4 vertexColor(VertexAttributes a) {
  return vec4(unpackHalf2x16(a.colorRG), unpackHalf2x16(a.colorBA));
}

// TEXCOORD_1 and COLOR_0 at barycentrics b (weights of v1, v2); uv0 is TEXCOORD_0 there.
// Without vertex attributes in the scene: TEXCOORD_0 for both sets and white, nothing read.
void sceneVertexAttributes(Triangle t, vec2 b, vec2 uv0, out vec4 uvs, out vec4 color) {
  uvs = uv0.xyxy;
  color = vec4(1.0);
  // The flag too: a pass that does not specialise on the scene's features has them all.
  if (!sceneHas(kSceneFeatureVertexAttributes) || gSceneInfo.vertexAttributes == 0u) return;
  VertexAttributes a0 = sceneVertexAttribute(t.v0), a1 = sceneVertexAttribute(t.v1),
                   a2 = sceneVertexAttribute(t.v2);
  float b0 = 1.0 - b.x - b.y;
  uvs.zw = a0.uv1 * b0 + a1.uv1 * b.x + a2.uv1 * b.y;
  color = vertexColor(a0) * b0 + vertexColor(a1) * b.x + vertexColor(a2) * b.y;
}

// Both uv sets (sampleTexture's uvs) at barycentrics b (weights of v1, v2).
vec4 sceneTexCoords(Triangle t, vec2 b, out vec4 color) {
  Vertex a = sceneVertex(t.v0), v1 = sceneVertex(t.v1), v2 = sceneVertex(t.v2);
  vec2 uv0 = vec2(a.u, a.v) * (1.0 - b.x - b.y) + vec2(v1.u, v1.v) * b.x + vec2(v2.u, v2.v) * b.y;
  vec4 uvs;
  sceneVertexAttributes(t, b, uv0, uvs, color);
  return uvs;
}

// glTF's alpha: base colour factor x texture x COLOR_0 alpha.
float materialAlpha(Material mat, vec4 uvs, vec4 color) {
  return mat.baseColor.a * sampleTexture(mat.baseColorTexture, uvs).a * color.a;
}

// The fraction of light a surface stops (its coverage): 1 for opaque materials, alpha for
// blended ones, 0 or 1 by the cutoff for masked ones. What a light sample on an emitter is
// weighted by, since a ray meets a blended surface with probability alpha (osrAlphaCutout).
float materialCoverage(Material mat, float alpha) {
  if (!sceneHas(kSceneFeatureAlphaTest)) return 1.0;
  if (sceneHas(kSceneFeatureAlphaBlend) && (mat.flags & kMaterialAlphaBlend) != 0u)
    return clamp(alpha, 0.0, 1.0);
  if ((mat.flags & kMaterialAlphaMask) != 0u) return alpha < mat.alphaCutoff ? 0.0 : 1.0;
  return 1.0;
}

// uvs: sceneTexCoords; color: COLOR_0 (white without).
SurfaceMaterial evaluateMaterial(Material mat, vec4 uv, vec4 color) {
  SurfaceMaterial m;
  vec4 base = sampleTexture(mat.baseColorTexture, uv);
  m.baseColor = mat.baseColor.rgb * srgbToLinear(base.rgb) * color.rgb;
  m.alpha = mat.baseColor.a * base.a * color.a;
  vec4 mr = sampleTexture(mat.metallicRoughnessTexture, uv);
  m.roughness = mat.roughness * mr.g;
  m.metallic = mat.metallic * mr.b;
  m.emission = mat.emission * srgbToLinear(sampleTexture(mat.emissiveTexture, uv).rgb);
  m.specular = mat.specular * sampleTexture(mat.specularTexture, uv).a;
  m.specularColor = mat.specularColor * srgbToLinear(sampleTexture(mat.specularColorTexture, uv).rgb);
  m.ior = mat.ior;
  m.transmission = mat.transmission * sampleTexture(mat.transmissionTexture, uv).r;
  m.doubleSided = (mat.flags & kMaterialDoubleSided) != 0u;
  m.clearcoat = 0.0;
  m.clearcoatRoughness = 0.0;
  m.sheenColor = vec3(0.0);
  m.sheenRoughness = 0.0;
  m.diffuseTransmissionColor = vec3(1.0);
  m.diffuseTransmission = 0.0;
  m.absorption = vec3(0.0);
  m.anisotropy = 0.0;
  m.anisotropyDirection = vec2(1.0, 0.0);
  m.iridescence = 0.0;
  m.iridescenceIor = 1.3;
  m.iridescenceThickness = 0.0;
  if (sceneHas(kSceneFeatureLayers)) {
    m.clearcoat = mat.clearcoat * sampleTexture(mat.clearcoatTexture, uv).r;
    m.clearcoatRoughness = mat.clearcoatRoughness * sampleTexture(mat.clearcoatRoughnessTexture, uv).g;
    m.sheenColor = mat.sheenColor * srgbToLinear(sampleTexture(mat.sheenColorTexture, uv).rgb);
    m.sheenRoughness = mat.sheenRoughness * sampleTexture(mat.sheenRoughnessTexture, uv).a;
    m.diffuseTransmission = mat.diffuseTransmission * sampleTexture(mat.diffuseTransmissionTexture, uv).a;
    m.diffuseTransmissionColor =
        mat.diffuseTransmissionColor * srgbToLinear(sampleTexture(mat.diffuseTransmissionColorTexture, uv).rgb);
    // thickness 0 is thin-walled (no medium inside); attenuationDistance 0 stands for infinity.
    if (mat.thickness > 0.0 && mat.attenuationDistance > 0.0)
      m.absorption = -log(max(mat.attenuationColor, vec3(1e-6))) / mat.attenuationDistance;
    vec4 an = sampleTexture(mat.anisotropyTexture, uv);
    m.anisotropy = mat.anisotropyStrength * (mat.anisotropyTexture >= 0 ? an.b : 1.0);
    vec2 d = mat.anisotropyTexture >= 0 ? an.rg * 2.0 - 1.0 : vec2(1.0, 0.0);
    d = length(d) > 1e-6 ? normalize(d) : vec2(1.0, 0.0);
    float c = cos(mat.anisotropyRotation), sn = sin(mat.anisotropyRotation);
    m.anisotropyDirection = vec2(c * d.x - sn * d.y, sn * d.x + c * d.y);
    if (mat.iridescence > 0.0) {
      m.iridescence = mat.iridescence * sampleTexture(mat.iridescenceTexture, uv).r;
      m.iridescenceIor = mat.iridescenceIor;
      m.iridescenceThickness =
          mat.iridescenceThicknessTexture >= 0
              ? mix(mat.iridescenceThicknessMinimum, mat.iridescenceThicknessMaximum,
                    sampleTexture(mat.iridescenceThicknessTexture, uv).g)
              : mat.iridescenceThicknessMaximum;
      // No film where it has no thickness (the Khronos sample renderer's rule): the
      // extension's series does not fall back to the base Fresnel there.
      if (!(m.iridescenceThickness > 0.0)) m.iridescence = 0.0;
    }
  }
  return m;
}

// A tangent-space normal map applied around nn, with the uv tangent frame (tangent, bitangent).
vec3 sceneNormalMap(int texture, float scale, vec4 uv, vec3 nn, vec3 tangent, vec3 bitangent) {
  vec3 tn = sampleTexture(texture, uv).xyz * 2.0 - 1.0;
  tn.xy *= scale;
  vec3 mapped = tangent * tn.x + bitangent * tn.y + nn * tn.z;
  float mLength = length(mapped);
  return mLength > 1e-12 ? mapped / mLength : nn;
}

// Full surface description at a hit. The shading normal is not flipped towards the viewer:
// the integrator decides (it knows the ray direction).
SurfaceSample surfaceAt(uint triangle, vec2 b) {
  Triangle t = sceneTriangle(triangle);
  Vertex v0 = sceneVertex(t.v0), v1 = sceneVertex(t.v1), v2 = sceneVertex(t.v2);
  float b0 = 1.0 - b.x - b.y;
  SurfaceSample s;
  s.position = v0.position * b0 + v1.position * b.x + v2.position * b.y;
  vec3 e1 = v1.position - v0.position, e2 = v2.position - v0.position;
  vec3 ng = cross(e1, e2);
  float ngLength = length(ng);
  s.geometricNormal = ngLength > 0.0 ? ng / ngLength : vec3(0.0, 0.0, 1.0);
  vec3 n = v0.normal * b0 + v1.normal * b.x + v2.normal * b.y;
  float nLength = length(n);
  // Zero-length vertex normals (degenerate input) fall back to the face normal.
  s.shadingNormal = nLength > 1e-12 ? n / nLength : s.geometricNormal;
  vec2 uv0 = vec2(v0.u, v0.v), uv1 = vec2(v1.u, v1.v), uv2 = vec2(v2.u, v2.v);
  vec4 color;
  sceneVertexAttributes(t, b, uv0 * b0 + uv1 * b.x + uv2 * b.y, s.uv, color);
  s.material = t.material;
  Material mat = sceneMaterial(t.material);
  s.m = evaluateMaterial(mat, s.uv, color);
  s.clearcoatNormal = s.shadingNormal;
  s.anisotropyTangent = vec3(0.0);
  bool layered = sceneHas(kSceneFeatureLayers) &&
                 (mat.clearcoatNormalTexture >= 0 || s.m.anisotropy > 0.0);
  if (mat.normalTexture >= 0 || layered) {
    // Tangent frame from the triangle's uv parameterization (the file's TANGENT attribute is
    // not loaded; for well-behaved uvs this is the per-face MikkTSpace result). The frame
    // follows the uv set of the normal map, else of the coat's normal map, else of the
    // anisotropy texture: one frame serves all three.
    int frameTexture = mat.normalTexture >= 0 ? mat.normalTexture
                       : mat.clearcoatNormalTexture >= 0 ? mat.clearcoatNormalTexture
                                                          : mat.anisotropyTexture;
    if (sceneHas(kSceneFeatureVertexAttributes) && gSceneInfo.vertexAttributes != 0u &&
        frameTexture >= 0 && (frameTexture & kTextureTexCoord1) != 0) {
      uv0 = sceneVertexAttribute(t.v0).uv1;
      uv1 = sceneVertexAttribute(t.v1).uv1;
      uv2 = sceneVertexAttribute(t.v2).uv1;
    }
    vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    float det = d1.x * d2.y - d1.y * d2.x;
    if (abs(det) > 1e-20) {
      vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
      vec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
      vec3 nn = s.shadingNormal;
      vec3 tangent = dpdu - nn * dot(nn, dpdu);
      float tLength = length(tangent);
      if (tLength > 1e-20) {
        tangent /= tLength;
        vec3 bitangent = cross(nn, tangent) * (dot(cross(nn, tangent), dpdv) < 0.0 ? -1.0 : 1.0);
        if (mat.normalTexture >= 0)
          s.shadingNormal = sceneNormalMap(mat.normalTexture, mat.normalScale, s.uv, nn, tangent, bitangent);
        if (layered && mat.clearcoatNormalTexture >= 0)
          s.clearcoatNormal = sceneNormalMap(mat.clearcoatNormalTexture, mat.clearcoatNormalScale,
                                             s.uv, nn, tangent, bitangent);
        if (layered && s.m.anisotropy > 0.0)
          s.anisotropyTangent = normalize(tangent * s.m.anisotropyDirection.x +
                                          bitangent * s.m.anisotropyDirection.y);
      }
    }
  }
  return s;
}

// Uniform number in [0, 1) for the stochastic transparency of `triangle` met by the ray
// (origin, 1 / direction as the traversal keeps it): a hash of the ray's bits and the
// triangle. Every ray of every integrator is drawn from continuous random numbers, so its bits
// differ from sample to sample and pixel to pixel and the hash is a fresh number per ray and
// hit; the same ray meeting the same triangle decides alike in every query.
float alphaHashNumber(uint triangle, vec3 origin, vec3 invDir) {
  uvec3 o = floatBitsToUint(origin), d = floatBitsToUint(invDir);
  uint h = sceneHash(o.x ^ sceneHash(o.y ^ sceneHash(o.z ^ sceneHash(d.x ^ sceneHash(d.y ^
           sceneHash(d.z ^ sceneHash(triangle)))))));
  return float(h >> 8) * (1.0 / 16777216.0);
}

// Any-hit test: true when the ray (origin, 1 / direction) goes on through this hit: in a hole
// of a masked material (alpha < cutoff, exact), or, on a blended one, with probability
// 1 - alpha (stochastic transparency: the ray meets the surface with probability alpha, so
// every estimator sees coverage alpha on average). Opaque materials ignore alpha.
bool osrAlphaCutout(uint triangle, vec2 b, vec3 origin, vec3 invDir) {
  if (!sceneHas(kSceneFeatureAlphaTest)) return false;
  Triangle t = sceneTriangle(triangle);
  Material mat = sceneMaterial(t.material);
  if ((mat.flags & (kMaterialAlphaMask | kMaterialAlphaBlend)) == 0u) return false;
  vec4 color;
  vec4 uvs = sceneTexCoords(t, b, color);
  float alpha = materialAlpha(mat, uvs, color);
  if (sceneHas(kSceneFeatureAlphaBlend) && (mat.flags & kMaterialAlphaBlend) != 0u)
    return alphaHashNumber(triangle, origin, invDir) >= alpha;
  return alpha < mat.alphaCutoff;
}

// ---- Environment ----------------------------------------------------------------------------
// Equirectangular, matching Blender's world mapping for a +Y-up glTF export: u = 0.5 +
// atan2(z, x) / 2pi, v (from the top row) = acos(y) / pi. Radiance is piecewise constant per
// texel so that environmentPdf() is exact for sampleEnvironment().

vec3 environmentDirection(vec2 uv) {
  float phi = (uv.x - 0.5) * 2.0 * kScenePi;
  float theta = uv.y * kScenePi;
  float st = sin(theta);
  return vec3(st * cos(phi), cos(theta), st * sin(phi));
}

vec2 environmentUv(vec3 dir) {
  float u = 0.5 + atan(dir.z, dir.x) / (2.0 * kScenePi);
  float v = acos(clamp(dir.y, -1.0, 1.0)) / kScenePi;
  return vec2(u, v);
}

uvec2 environmentTexel(vec2 uv) {
  uint w = gSceneInfo.envWidth, h = gSceneInfo.envHeight;
  return uvec2(min(uint(max(uv.x, 0.0) * float(w)), w - 1u), min(uint(max(uv.y, 0.0) * float(h)), h - 1u));
}

// Radiance arriving from direction `dir` (unit, world space); black without a map.
vec3 environmentRadiance(vec3 dir) {
  if (!sceneHas(kSceneFeatureEnvironment) || gSceneInfo.envWidth == 0u) return vec3(0.0);
  uvec2 p = environmentTexel(environmentUv(dir));
  return gEnvironment[p.y * gSceneInfo.envWidth + p.x].rgb * gSceneInfo.envScale;
}

// First index i in [first, first + count) with cdf[i] > u (the last one if none).
uint environmentSearch(uint first, uint count, float u) {
  uint lo = 0u, hi = count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (gEnvironmentCdf[first + mid] > u) hi = mid; else lo = mid + 1u;
  }
  return lo;
}

float environmentCdfStep(uint first, uint i) {
  return gEnvironmentCdf[first + i] - (i > 0u ? gEnvironmentCdf[first + i - 1u] : 0.0);
}

// Solid-angle density of sampleEnvironment() for direction `dir`; 0 without a map.
float environmentPdf(vec3 dir) {
  uint w = gSceneInfo.envWidth, h = gSceneInfo.envHeight;
  if (!sceneHas(kSceneFeatureEnvironment) || w == 0u) return 0.0;
  uvec2 p = environmentTexel(environmentUv(dir));
  float sinTheta = sqrt(max(0.0, 1.0 - dir.y * dir.y));
  if (sinTheta <= 0.0) return 0.0;
  float pRow = environmentCdfStep(0u, p.y), pCol = environmentCdfStep(h + p.y * w, p.x);
  return pRow * pCol * float(w * h) / (2.0 * kScenePi * kScenePi * sinTheta);
}

// Direction sampled proportionally to luminance x sin(theta) per texel; `u` uniform in [0,1)^2.
// Returns the direction; pdf (solid angle) and radiance for it are written out.
vec3 sampleEnvironment(vec2 u, out float pdf, out vec3 radiance) {
  uint w = gSceneInfo.envWidth, h = gSceneInfo.envHeight;
  if (!sceneHas(kSceneFeatureEnvironment) || w == 0u) {
    pdf = 0.0;
    radiance = vec3(0.0);
    return vec3(0.0, 1.0, 0.0);
  }
  uint y = environmentSearch(0u, h, u.y);
  uint rowFirst = h + y * w;
  uint x = environmentSearch(rowFirst, w, u.x);
  // Reuse the random numbers inside the chosen texel (stratified, no extra dimensions).
  float pRow = environmentCdfStep(0u, y), pCol = environmentCdfStep(rowFirst, x);
  float fy = pRow > 0.0 ? clamp((u.y - (gEnvironmentCdf[y] - pRow)) / pRow, 0.0, 1.0) : 0.5;
  float fx = pCol > 0.0 ? clamp((u.x - (gEnvironmentCdf[rowFirst + x] - pCol)) / pCol, 0.0, 1.0) : 0.5;
  vec2 uv = vec2((float(x) + fx) / float(w), (float(y) + fy) / float(h));
  vec3 dir = environmentDirection(uv);
  float sinTheta = sin(uv.y * kScenePi);
  pdf = sinTheta > 0.0 ? pRow * pCol * float(w * h) / (2.0 * kScenePi * kScenePi * sinTheta) : 0.0;
  radiance = gEnvironment[y * w + x].rgb * gSceneInfo.envScale;
  return dir;
}

#endif
