// The path tracer's passes (pt_trace.comp): film layout, per-frame constants, bindings.
#ifndef OSR_SHARED_PT_H
#define OSR_SHARED_PT_H
#include "shared/bvh.h"
#include "shared/scene.h"
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(pt)

OSR_CONST(uint, kPtWorkgroupSize, 64);

// Bindings of pt_trace.comp: its own buffers, then the BVH's, then the scene's.
OSR_CONST(uint, kPtBindingFilm, 0u);
OSR_CONST(uint, kPtBindingFrame, 1u);
OSR_CONST(uint, kPtBvhBinding, 2u);
OSR_CONST(uint, kPtSceneBinding, 6u);   // kPtBvhBinding + kBvhBindingCount
OSR_CONST(uint, kPtSceneTexelBinding, 16u);  // kPtSceneBinding + kSceneBindingCount
OSR_CONST(uint, kPtBindingCount, 19u);  // kPtSceneTexelBinding + kSceneTexelBindingCount

// Specialization constant 0 of pt_trace.comp: what a sample computes.
OSR_CONST(uint, kPtSpecIntegrator, 0u);
OSR_CONST(uint, kIntegratorPath, 0u);     // unidirectional path tracing, NEE + MIS
OSR_CONST(uint, kIntegratorPreview, 1u);  // primary hit: albedo x headlight cosine
// Specialization constant 1 of pt_trace.comp: the scene's kSceneFeature* bits.
OSR_CONST(uint, kPtSpecSceneFeatures, 1u);

// Running sums per pixel; the host divides by the sample count (combined.w).
// direct: emission seen directly plus light after one bounce; indirect: after more than one
// bounce (combined = direct + indirect). albedo, normal (world, facing the camera) and depth
// (distance along the camera's view axis, x = sum, y = number of samples that hit) are of the
// first surface.
struct FilmPixel {
  vec4 combined;
  vec4 direct;
  vec4 indirect;
  vec4 albedo;
  vec4 normal;
  vec4 depth;
};

// Per-render constants (one small buffer).
struct Frame {
  vec4 cameraRight;  // worldFromCamera columns: +X
  vec4 cameraUp;     // +Y
  vec4 cameraBack;   // +Z (the camera looks down -Z)
  vec4 cameraOrigin;
  uint width;
  uint height;
  uint seed;
  uint _pad0;
  float tanHalfFovY;
  float aspect;  // width / height of the image
  float _pad1;
  float _pad2;
};

// One dispatch: pixels [pixelOffset, pixelOffset + pixelCount), samples with indices
// [sampleIndex, sampleIndex + sampleCount).
struct Push {
  uint pixelOffset;
  uint pixelCount;
  uint sampleIndex;
  uint sampleCount;
};

OSR_NAMESPACE_END
#endif
