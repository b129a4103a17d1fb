// Scene data as the device sees it (std430). Written by src/scene_gpu (upload), read by every
// pass that shades: see shaders/lib/scene.glsl for the accessors.
#ifndef OSR_SHARED_SCENE_H
#define OSR_SHARED_SCENE_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(scene)

// Material flags.
OSR_CONST(uint, kMaterialDoubleSided, 1u);
OSR_CONST(uint, kMaterialAlphaMask, 2u);   // alpha < alphaCutoff is a hole
// Blended: a ray meets the surface with probability alpha (stochastic transparency,
// lib/scene.glsl osrAlphaCutout), so every estimator sees coverage alpha on average.
OSR_CONST(uint, kMaterialAlphaBlend, 4u);
OSR_CONST(int, kNoTexture, -1);
// A material's texture field is a texture reference: the index into the textures, with
// kTextureTexCoord1 set where the glTF textureInfo says texCoord 1 (the slot reads
// VertexAttributes.uv1), or kNoTexture.
OSR_CONST(int, kTextureTexCoord1, 0x40000000);
OSR_CONST(int, kTextureIndexMask, 0x3fffffff);

// One vertex in world space (all node transforms applied at load).
struct Vertex {
  vec3 position;
  float u;
  vec3 normal;  // unit shading normal (geometric normal where the file has none)
  float v;
};

// What a vertex carries beyond Vertex, stored only where some primitive has COLOR_0 or
// TEXCOORD_1 (kSceneFeatureVertexAttributes): after the textures' texels in the texel buffer
// (4 words per vertex from word SceneInfo.vertexAttributes), since OSR's passes have no push
// descriptor left for a buffer of their own (lavapipe's maxPushDescriptors is 32).
struct VertexAttributes {
  uint colorRG;  // COLOR_0 (linear RGBA, white where the primitive has none) as two
  uint colorBA;  // packHalf2x16 words: R | G << 16, B | A << 16
  vec2 uv1;      // TEXCOORD_1 with the material's texture transform; TEXCOORD_0's where none
};

// Triangle: vertex indices and material, one uvec4 per triangle.
struct Triangle {
  uint v0;
  uint v1;
  uint v2;
  uint material;
};

// glTF metallic-roughness material with the extensions of DESIGN.md. Factors are linear.
struct Material {
  vec4 baseColor;       // baseColorFactor (RGBA)
  vec3 emission;        // emissiveFactor * KHR_materials_emissive_strength: radiance
  float roughness;      // perceptual roughness factor
  vec3 specularColor;   // KHR_materials_specular specularColorFactor (default 1)
  float metallic;
  float specular;       // KHR_materials_specular specularFactor (default 1)
  float ior;            // KHR_materials_ior (default 1.5)
  float transmission;   // KHR_materials_transmission factor
  float alphaCutoff;    // for kMaterialAlphaMask (default 0.5)
  int baseColorTexture;          // index into textures or kNoTexture; sRGB
  int metallicRoughnessTexture;  // G = roughness, B = metallic; linear
  int normalTexture;             // tangent-space normal map; linear
  int emissiveTexture;           // sRGB
  int transmissionTexture;       // R; linear
  int specularTexture;           // A; linear
  int specularColorTexture;      // RGB; sRGB
  uint flags;
  float normalScale;
  // Layered lobes (shaders/lib/bsdf.glsl); a zero factor disables the lobe.
  float clearcoat;           // KHR_materials_clearcoat clearcoatFactor
  float clearcoatRoughness;  // clearcoatRoughnessFactor (perceptual)
  float clearcoatNormalScale;
  vec3 sheenColor;           // KHR_materials_sheen sheenColorFactor
  float sheenRoughness;      // sheenRoughnessFactor (perceptual)
  vec3 attenuationColor;     // KHR_materials_volume (default 1: no absorption)
  float attenuationDistance; // metres; 0 = infinite (no absorption)
  vec3 diffuseTransmissionColor;  // KHR_materials_diffuse_transmission colour (default 1)
  float diffuseTransmission;      // diffuseTransmissionFactor
  int clearcoatTexture;           // R; linear
  int clearcoatRoughnessTexture;  // G; linear
  int clearcoatNormalTexture;     // tangent-space normal map of the coat; linear
  int sheenColorTexture;          // RGB; sRGB
  int sheenRoughnessTexture;      // A; linear
  int diffuseTransmissionTexture;       // A; linear
  int diffuseTransmissionColorTexture;  // RGB; sRGB
  int anisotropyTexture;  // RG: direction in [-1, 1] (tangent, bitangent), B: strength; linear
  float anisotropyStrength;  // KHR_materials_anisotropy
  float anisotropyRotation;  // radians, counter-clockwise from the uv tangent
  float thickness;           // KHR_materials_volume thicknessFactor; 0 = thin-walled
  float iridescence;                  // KHR_materials_iridescence iridescenceFactor
  float iridescenceIor;               // the film's ior (default 1.3)
  float iridescenceThicknessMinimum;  // nanometres (default 100)
  float iridescenceThicknessMaximum;  // nanometres (default 400): the thickness without texture
  int iridescenceTexture;             // R; linear
  int iridescenceThicknessTexture;    // G: mix(minimum, maximum, g); linear
  float _pad0;
  float _pad1;
  float _pad2;
};

// Material read as RGBA32UI texels (lib/scene.glsl sceneMaterial with texel fetch): element i
// is texels [i * kMaterialTexels, (i + 1) * kMaterialTexels), and a field whose first 32-bit
// word is w sits in texel w / 4, lane w % 4 (vec3/vec4 fields continue in the next lanes).
// The word offsets are the std430 offsets of Material / 4; C++ static_asserts them against
// offsetof (src/scene_gpu/gpu_scene.cpp, tests/vk/test_shared_layout.cpp).
OSR_CONST(uint, kMaterialTexels, 15u);  // sizeof(Material) / 16
// Texels of the base material alone (words 0-24): passes that know the scene uses no layered
// lobe (kSceneFeatureLayers) fetch only these.
OSR_CONST(uint, kMaterialBaseTexels, 7u);
OSR_CONST(uint, kMaterialWordBaseColor, 0u);
OSR_CONST(uint, kMaterialWordEmission, 4u);
OSR_CONST(uint, kMaterialWordRoughness, 7u);
OSR_CONST(uint, kMaterialWordSpecularColor, 8u);
OSR_CONST(uint, kMaterialWordMetallic, 11u);
OSR_CONST(uint, kMaterialWordSpecular, 12u);
OSR_CONST(uint, kMaterialWordIor, 13u);
OSR_CONST(uint, kMaterialWordTransmission, 14u);
OSR_CONST(uint, kMaterialWordAlphaCutoff, 15u);
OSR_CONST(uint, kMaterialWordBaseColorTexture, 16u);
OSR_CONST(uint, kMaterialWordMetallicRoughnessTexture, 17u);
OSR_CONST(uint, kMaterialWordNormalTexture, 18u);
OSR_CONST(uint, kMaterialWordEmissiveTexture, 19u);
OSR_CONST(uint, kMaterialWordTransmissionTexture, 20u);
OSR_CONST(uint, kMaterialWordSpecularTexture, 21u);
OSR_CONST(uint, kMaterialWordSpecularColorTexture, 22u);
OSR_CONST(uint, kMaterialWordFlags, 23u);
OSR_CONST(uint, kMaterialWordNormalScale, 24u);
OSR_CONST(uint, kMaterialWordClearcoat, 25u);
OSR_CONST(uint, kMaterialWordClearcoatRoughness, 26u);
OSR_CONST(uint, kMaterialWordClearcoatNormalScale, 27u);
OSR_CONST(uint, kMaterialWordSheenColor, 28u);
OSR_CONST(uint, kMaterialWordSheenRoughness, 31u);
OSR_CONST(uint, kMaterialWordAttenuationColor, 32u);
OSR_CONST(uint, kMaterialWordAttenuationDistance, 35u);
OSR_CONST(uint, kMaterialWordDiffuseTransmissionColor, 36u);
OSR_CONST(uint, kMaterialWordDiffuseTransmission, 39u);
OSR_CONST(uint, kMaterialWordClearcoatTexture, 40u);
OSR_CONST(uint, kMaterialWordClearcoatRoughnessTexture, 41u);
OSR_CONST(uint, kMaterialWordClearcoatNormalTexture, 42u);
OSR_CONST(uint, kMaterialWordSheenColorTexture, 43u);
OSR_CONST(uint, kMaterialWordSheenRoughnessTexture, 44u);
OSR_CONST(uint, kMaterialWordDiffuseTransmissionTexture, 45u);
OSR_CONST(uint, kMaterialWordDiffuseTransmissionColorTexture, 46u);
OSR_CONST(uint, kMaterialWordAnisotropyTexture, 47u);
OSR_CONST(uint, kMaterialWordAnisotropyStrength, 48u);
OSR_CONST(uint, kMaterialWordAnisotropyRotation, 49u);
OSR_CONST(uint, kMaterialWordThickness, 50u);
OSR_CONST(uint, kMaterialWordIridescence, 51u);
OSR_CONST(uint, kMaterialWordIridescenceIor, 52u);
OSR_CONST(uint, kMaterialWordIridescenceThicknessMinimum, 53u);
OSR_CONST(uint, kMaterialWordIridescenceThicknessMaximum, 54u);
OSR_CONST(uint, kMaterialWordIridescenceTexture, 55u);
OSR_CONST(uint, kMaterialWordIridescenceThicknessTexture, 56u);

#ifdef __cplusplus
// The texel layout above is Material's: a field moved or added without its constant fails here.
#include <cstddef>
#define OSR_MATERIAL_WORD(field, word) \
  static_assert(offsetof(Material, field) == 4 * (word), "kMaterialWord of " #field)
OSR_MATERIAL_WORD(baseColor, kMaterialWordBaseColor);
OSR_MATERIAL_WORD(emission, kMaterialWordEmission);
OSR_MATERIAL_WORD(roughness, kMaterialWordRoughness);
OSR_MATERIAL_WORD(specularColor, kMaterialWordSpecularColor);
OSR_MATERIAL_WORD(metallic, kMaterialWordMetallic);
OSR_MATERIAL_WORD(specular, kMaterialWordSpecular);
OSR_MATERIAL_WORD(ior, kMaterialWordIor);
OSR_MATERIAL_WORD(transmission, kMaterialWordTransmission);
OSR_MATERIAL_WORD(alphaCutoff, kMaterialWordAlphaCutoff);
OSR_MATERIAL_WORD(baseColorTexture, kMaterialWordBaseColorTexture);
OSR_MATERIAL_WORD(metallicRoughnessTexture, kMaterialWordMetallicRoughnessTexture);
OSR_MATERIAL_WORD(normalTexture, kMaterialWordNormalTexture);
OSR_MATERIAL_WORD(emissiveTexture, kMaterialWordEmissiveTexture);
OSR_MATERIAL_WORD(transmissionTexture, kMaterialWordTransmissionTexture);
OSR_MATERIAL_WORD(specularTexture, kMaterialWordSpecularTexture);
OSR_MATERIAL_WORD(specularColorTexture, kMaterialWordSpecularColorTexture);
OSR_MATERIAL_WORD(flags, kMaterialWordFlags);
OSR_MATERIAL_WORD(normalScale, kMaterialWordNormalScale);
OSR_MATERIAL_WORD(clearcoat, kMaterialWordClearcoat);
OSR_MATERIAL_WORD(clearcoatRoughness, kMaterialWordClearcoatRoughness);
OSR_MATERIAL_WORD(clearcoatNormalScale, kMaterialWordClearcoatNormalScale);
OSR_MATERIAL_WORD(sheenColor, kMaterialWordSheenColor);
OSR_MATERIAL_WORD(sheenRoughness, kMaterialWordSheenRoughness);
OSR_MATERIAL_WORD(attenuationColor, kMaterialWordAttenuationColor);
OSR_MATERIAL_WORD(attenuationDistance, kMaterialWordAttenuationDistance);
OSR_MATERIAL_WORD(diffuseTransmissionColor, kMaterialWordDiffuseTransmissionColor);
OSR_MATERIAL_WORD(diffuseTransmission, kMaterialWordDiffuseTransmission);
OSR_MATERIAL_WORD(clearcoatTexture, kMaterialWordClearcoatTexture);
OSR_MATERIAL_WORD(clearcoatRoughnessTexture, kMaterialWordClearcoatRoughnessTexture);
OSR_MATERIAL_WORD(clearcoatNormalTexture, kMaterialWordClearcoatNormalTexture);
OSR_MATERIAL_WORD(sheenColorTexture, kMaterialWordSheenColorTexture);
OSR_MATERIAL_WORD(sheenRoughnessTexture, kMaterialWordSheenRoughnessTexture);
OSR_MATERIAL_WORD(diffuseTransmissionTexture, kMaterialWordDiffuseTransmissionTexture);
OSR_MATERIAL_WORD(diffuseTransmissionColorTexture, kMaterialWordDiffuseTransmissionColorTexture);
OSR_MATERIAL_WORD(anisotropyTexture, kMaterialWordAnisotropyTexture);
OSR_MATERIAL_WORD(anisotropyStrength, kMaterialWordAnisotropyStrength);
OSR_MATERIAL_WORD(anisotropyRotation, kMaterialWordAnisotropyRotation);
OSR_MATERIAL_WORD(thickness, kMaterialWordThickness);
OSR_MATERIAL_WORD(iridescence, kMaterialWordIridescence);
OSR_MATERIAL_WORD(iridescenceIor, kMaterialWordIridescenceIor);
OSR_MATERIAL_WORD(iridescenceThicknessMinimum, kMaterialWordIridescenceThicknessMinimum);
OSR_MATERIAL_WORD(iridescenceThicknessMaximum, kMaterialWordIridescenceThicknessMaximum);
OSR_MATERIAL_WORD(iridescenceTexture, kMaterialWordIridescenceTexture);
OSR_MATERIAL_WORD(iridescenceThicknessTexture, kMaterialWordIridescenceThicknessTexture);
#undef OSR_MATERIAL_WORD
static_assert(sizeof(Material) == 16 * kMaterialTexels, "kMaterialTexels");
#endif

// lowbias32 (Wellons): a 32-bit integer hash with good avalanche, written once for GLSL and
// C++ (the stochastic transparency of lib/scene.glsl alphaHashNumber and its C++ twin).
#ifdef __cplusplus
#define OSR_SCENE_FN inline
#else
#define OSR_SCENE_FN
#endif
OSR_SCENE_FN uint sceneHash(uint x) {
  x ^= x >> 16u;
  x *= 0x7feb352du;
  x ^= x >> 15u;
  x *= 0x846ca68bu;
  x ^= x >> 16u;
  return x;
}

// Texture wrap modes (glTF sampler), in TextureInfo.wrap: S in bits 0-1, T in bits 2-3.
OSR_CONST(uint, kWrapRepeat, 0u);
OSR_CONST(uint, kWrapClamp, 1u);
OSR_CONST(uint, kWrapMirror, 2u);
// Also in TextureInfo.wrap: the sampler's magFilter is NEAREST (default: bilinear).
OSR_CONST(uint, kTextureNearest, 16u);

// A texture's texels are RGBA8 (one uint each, R in the low byte) in the shared texel buffer.
struct TextureInfo {
  uint offset;  // first texel in the texel buffer
  uint width;
  uint height;
  uint wrap;
};

// An emissive triangle for light sampling, chosen with probability proportional to power.
struct EmissiveTriangle {
  uint triangle;  // index into the triangle buffer
  float power;    // luminance(emission x mean emissive texture) * area * pi, x2 if double-sided
  float cdf;      // inclusive prefix sum of power / total power
  float area;
};

// KHR_lights_punctual.
OSR_CONST(uint, kLightPoint, 0u);
OSR_CONST(uint, kLightSpot, 1u);
OSR_CONST(uint, kLightDirectional, 2u);
struct PunctualLight {
  vec3 position;     // world space
  uint type;
  vec3 direction;    // world space, direction the light points in (unit)
  float range;       // 0 = infinite
  vec3 intensity;    // color * intensity / 683 lm/W: W/sr (point, spot), W/m^2 (directional)
  float cosInner;    // spot inner cone cosine
  float cosOuter;    // spot outer cone cosine
  float _pad0;
  float _pad1;
  float _pad2;
};

// Scene-wide counts and the environment map, in one small buffer every shading pass binds.
struct SceneInfo {
  uint triangleCount;
  uint emissiveCount;
  uint lightCount;
  uint envWidth;       // 0: no environment map (black world)
  uint envHeight;
  float envScale;      // radiance multiplier
  float emissivePower; // total power of emissive triangles
  uint vertexAttributes;  // first word of the VertexAttributes in gTexels; 0: none
  vec4 boundsMin;
  vec4 boundsMax;
};

// What a scene uses (GpuScene::features), for passes to specialise on: lib/scene.glsl compiles
// the code of an absent feature out when the includer defines OSR_SCENE_FEATURES (e.g. as a
// specialization constant; default kSceneFeatureAll). On lavapipe a divergent branch runs for
// all SIMD lanes under a mask, so code no lane needs still costs its full time.
OSR_CONST(uint, kSceneFeatureAlphaTest, 1u);    // some material is alpha-masked or blended
OSR_CONST(uint, kSceneFeatureTextures, 2u);     // some texture
OSR_CONST(uint, kSceneFeaturePunctual, 4u);     // some KHR_lights_punctual light
OSR_CONST(uint, kSceneFeatureEnvironment, 8u);  // an environment map
OSR_CONST(uint, kSceneFeatureTransmission, 16u);  // some material with transmission > 0
// Some material with a layered lobe: clearcoat, sheen, diffuse transmission, anisotropy,
// iridescence or an absorbing volume (KHR_materials_*; the material words past kMaterialBaseTexels).
OSR_CONST(uint, kSceneFeatureLayers, 32u);
OSR_CONST(uint, kSceneFeatureVertexAttributes, 64u);  // some COLOR_0 or TEXCOORD_1
OSR_CONST(uint, kSceneFeatureAlphaBlend, 128u);  // some material is blended (hashed coverage)
OSR_CONST(uint, kSceneFeatureAll, 255u);

// Binding slots of the scene buffers, relative to the first slot a pass gives them
// (OSR_SCENE_BINDING in GLSL); GpuScene::bindings() returns the buffers in this order.
OSR_CONST(uint, kSceneBindingVertices, 0u);
OSR_CONST(uint, kSceneBindingTriangles, 1u);
OSR_CONST(uint, kSceneBindingMaterials, 2u);
OSR_CONST(uint, kSceneBindingTextureInfos, 3u);
OSR_CONST(uint, kSceneBindingTexels, 4u);
OSR_CONST(uint, kSceneBindingLights, 5u);
OSR_CONST(uint, kSceneBindingEmissive, 6u);
OSR_CONST(uint, kSceneBindingInfo, 7u);
OSR_CONST(uint, kSceneBindingEnvironment, 8u);
OSR_CONST(uint, kSceneBindingEnvironmentCdf, 9u);
OSR_CONST(uint, kSceneBindingCount, 10u);

// Optional RGBA32UI texel views of the hottest scene buffers (GpuScene::texelViews), relative
// to OSR_SCENE_TEXEL_BINDING; a pass that defines it reads vertices, triangles and materials
// by texel fetch where specialization constant kSceneSpecTexelFetch is true (on lavapipe a
// gather instead of a per-lane loop). Texels per element: Vertex 2, Triangle 1, Material
// kMaterialTexels.
OSR_CONST(uint, kSceneTexelBindingVertices, 0u);
OSR_CONST(uint, kSceneTexelBindingTriangles, 1u);
OSR_CONST(uint, kSceneTexelBindingMaterials, 2u);
OSR_CONST(uint, kSceneTexelBindingCount, 3u);
OSR_CONST(uint, kSceneSpecTexelFetch, 201u);  // constant_id; see kBvhSpecTexelFetch

OSR_NAMESPACE_END
#endif
