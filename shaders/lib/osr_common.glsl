// What every OSR pass (osr_*.comp) includes: the shared records and bindings of shared/osr.h,
// the scene, BVH traversal and the shading building blocks, specialised on the scene's
// features. A pass declares only its own push block (shared/osr.h, one struct per pass) and
// workgroup size.
#ifndef OSR_LIB_OSR_COMMON_GLSL
#define OSR_LIB_OSR_COMMON_GLSL
#extension GL_GOOGLE_include_directive : require
#include "shared/osr.h"
#include "shared/film.h"

#define OSR_SCENE_BINDING kOsrSceneBinding
#define OSR_SCENE_TEXEL_BINDING kOsrSceneTexelBinding
layout(constant_id = kOsrSpecSceneFeatures) const uint kSceneFeatures = kSceneFeatureAll;
#define OSR_SCENE_FEATURES kSceneFeatures
#include "lib/scene.glsl"
#define OSR_BVH_BINDING kOsrBvhBinding
#define OSR_BVH_ALPHA_TEST
#include "lib/bvh_traverse.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#define OSR_BSDF_TRANSMISSION ((kSceneFeatures & kSceneFeatureTransmission) != 0u)
#define OSR_BSDF_LAYERS ((kSceneFeatures & kSceneFeatureLayers) != 0u)
#include "lib/bsdf.glsl"
#include "lib/ray_offset.glsl"
#include "lib/lights.glsl"
#include "lib/shading.glsl"
#include "lib/path.glsl"
#include "lib/camera.glsl"

layout(std430, binding = kOsrBindingFrame) readonly buffer OsrFrameBlock { CameraFrame gFrame; };
layout(std430, binding = kOsrBindingGBuffer) buffer OsrGBuffer { GBufferPixel gGBuffer[]; };
layout(std430, binding = kOsrBindingAccum) buffer OsrAccum { AccumPixel gAccum[]; };
layout(std430, binding = kOsrBindingMapPoints) buffer OsrMapPoints { MapPoint gMapPoints[]; };
layout(std430, binding = kOsrBindingMapProjections) buffer OsrMapProjections {
  MapProjection gMapProjections[];
};
layout(std430, binding = kOsrBindingMapClean) buffer OsrMapClean { float gMapClean[]; };

// Random stream salts, so the passes of one progressive pass draw independent numbers.
const uint kSaltGBuffer = 0x1b873593u;
const uint kSaltDirect = 0x85ebca6bu;
const uint kSaltMaps = 0xc2b2ae35u;
const uint kSaltComposite = 0x27d4eb2fu;
const uint kSaltResidual = 0x165667b1u;

Rng passRng(uint pass, uint index, uint salt) { return rngInit(index, pass, gFrame.seed ^ salt); }
// The stream of film pixel `pixel` in pass `pass`, keyed on its place in the whole image
// (lib/camera.glsl), so that a --crop window draws the whole image's numbers.
Rng pixelRng(uint pass, uint pixel, uint salt) {
  return passRng(pass, imagePixelIndex(gFrame, pixel), salt);
}

// The G-buffer's surface as a shading point (the frame is rebuilt from the stored normal).
ShadingPoint gbufferShadingPoint(GBufferPixel g) {
  ShadingPoint sp;
  sp.position = g.position.xyz;
  sp.ng = g.geomNormal.xyz;
  sp.ns = g.normal.xyz;
  sp.front = g.geomNormal.w > 0.5;
  sp.wo = g.wo.xyz;
  frameFromNormal(sp.ns, sp.t, sp.b);
  sp.woLocal = toLocal(sp.wo, sp.t, sp.b, sp.ns);
  sp.bsdf = g.bsdf;
  return sp;
}

bool finite3(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

#endif
