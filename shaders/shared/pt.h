// The path tracer's passes (pt_trace.comp): film layout, per-frame constants, bindings.
#ifndef OSR_SHARED_PT_H
#define OSR_SHARED_PT_H
#include "shared/bvh.h"
#include "shared/camera.h"
#include "shared/film.h"
#include "shared/scene.h"
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(pt)

OSR_CONST(uint, kPtWorkgroupSize, 64);

// Bindings of pt_trace.comp: its own buffers, then the BVH's, then the scene's.
OSR_CONST(uint, kPtBindingFilm, 0u);
OSR_CONST(uint, kPtBindingFrame, 1u);  // gpu::camera::CameraFrame
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
