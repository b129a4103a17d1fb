// One Shot Radiance (DESIGN.md "OSR pass"): the G-buffer, accumulation and hemisphere-map
// records every osr_*.comp pass shares with src/osr, their binding slots, push constants and
// the small formulas (interpolation weights, normalization) the host tests twin.
//
// Every OSR pass uses one binding layout (kOsrBinding*): the pass's buffers, then the BVH,
// then the scene; a pass declares the slots it reads and src/osr binds all of them by name.
#ifndef OSR_SHARED_OSR_H
#define OSR_SHARED_OSR_H
#include "shared/bsdf.h"
#include "shared/bvh.h"
#include "shared/camera.h"
#include "shared/hemisphere.h"
#include "shared/scene.h"
#include "shared/types.h"

#ifdef __cplusplus
#include <cmath>
#define OSR_OSR_FN inline
#else
#define OSR_OSR_FN
#endif

OSR_NAMESPACE_BEGIN(osr)
#ifdef __cplusplus
using glm::abs;
using glm::dot;
using glm::max;
using glm::min;
using std::ceil;
using std::exp;
using std::log;
using std::log2;
using bsdf::BsdfParams;
#endif

OSR_CONST(uint, kOsrWorkgroupSize, 64);
OSR_CONST(uint, kMapChannels, 7u);  // one-shot input: radiance RGB, hit normal XYZ, distance

// Binding slots (one layout for every OSR pass). Per-pixel and clean-map buffers can be larger
// than one binding (3840 x 2160 pixels of GBufferPixel is 1 GiB; lavapipe binds 128 MiB), so
// src/osr/osr_pass.cpp binds windows of them (render/film.h): in a pixel pass, element 0 of
// gGBuffer, gAccum and gFilm is pixel pixelOffset and element 0 of gMapClean is map
// cleanMapOffset; in the map passes, element 0 of gMapClean is the chunk's first map; in
// osr_maps, element 0 of gGBuffer is pixel gbufferWindowOffset.
OSR_CONST(uint, kOsrBindingFrame, 0u);           // camera::CameraFrame
OSR_CONST(uint, kOsrBindingGBuffer, 1u);         // GBufferPixel[pixel window]
OSR_CONST(uint, kOsrBindingAccum, 2u);           // AccumPixel[pixel window]
OSR_CONST(uint, kOsrBindingMapPoints, 3u);       // MapPoint[maps of the pass]: osr_maps writes
OSR_CONST(uint, kOsrBindingMapProjections, 4u);  // MapProjection[maps]: osr_map_project writes
OSR_CONST(uint, kOsrBindingMapClean, 5u);    // float[map window][3][32][32]: denoised radiance
OSR_CONST(uint, kOsrBindingMapOneShot, 6u);  // float[chunk maps][7][32][32]: traced input
OSR_CONST(uint, kOsrBindingMapStats, 7u);    // MapStats[chunk maps]
OSR_CONST(uint, kOsrBindingNetIn, 8u);       // float[chunk maps][7][32][32]: normalized
OSR_CONST(uint, kOsrBindingNetOut, 9u);      // float[chunk maps][3][32][32]: U-Net output
OSR_CONST(uint, kOsrBindingFilm, 10u);       // film::FilmPixel[pixel window] (resolve)
OSR_CONST(uint, kOsrBvhBinding, 11u);        // + kBvhBindingCount
OSR_CONST(uint, kOsrSceneBinding, 15u);      // + kSceneBindingCount
OSR_CONST(uint, kOsrSceneTexelBinding, 25u);  // + kSceneTexelBindingCount
// The world-space map cache (src/osr/map_cache.h, docs/osr.md "The map cache").
OSR_CONST(uint, kOsrBindingCacheEntries, 28u);  // MapCacheEntry[slots]
OSR_CONST(uint, kOsrBindingCacheClean, 29u);    // float[slots][3][32][32]: the cached clean maps
OSR_CONST(uint, kOsrBindingCacheClaims, 30u);   // uint[slots]: the store's claims (kMapCacheNone)
OSR_CONST(uint, kOsrBindingCacheRefs, 31u);     // MapCacheRef[maps of the pass]
OSR_CONST(uint, kOsrBindingCount, 32u);

// Specialization constants.
OSR_CONST(uint, kOsrSpecSceneFeatures, 0u);  // the scene's kSceneFeature* bits
OSR_CONST(uint, kOsrSpecDenoiser, 1u);       // osr_map_denoise: kDenoiser*
OSR_CONST(uint, kOsrSpecNetOutput, 2u);      // osr_map_denoise: kNetOutput*
OSR_CONST(uint, kOsrSpecMapByGroup, 3u);     // osr_map_denoise: 1 = a workgroup per map
OSR_CONST(uint, kDenoiserUnet, 0u);   // the U-Net's output, denormalized
OSR_CONST(uint, kDenoiserBlur, 1u);   // a fixed Gaussian blur of the one-shot radiance
OSR_CONST(uint, kDenoiserNone, 2u);   // the one-shot radiance as traced

// How the U-Net's output y becomes radiance (the weights' normalization, nn/weights_format.h).
OSR_CONST(uint, kNetOutputRescaled, 0u);  // exp(y) - 1, each channel rescaled to the one-shot mean
OSR_CONST(uint, kNetOutputAbsolute, 1u);  // 10 m (exp(y) - 1), m the one-shot mean of all channels

// Near-specular surfaces (lib/bsdf.glsl bsdfNearSpecular) the G-buffer follows, at most.
OSR_CONST(uint, kMaxSpecularChain, 8u);
// Lobes narrower than about a texel of a 32 x 32 map (GGX alpha below this) are not looked up
// in maps: the residual path tracer answers for them in full.
OSR_CONST(float, kNarrowLobeAlpha, 0.05f);

// The first surface through a pixel that is not near-specular, for this pass's jitter.
struct GBufferPixel {
  vec4 position;    // xyz: world position; w: 1 valid surface, 0 none (missed, absorbed)
  vec4 normal;      // xyz: shading normal facing wo (below-horizon fallback applied)
  vec4 geomNormal;  // xyz: geometric normal facing wo; w: 1 front face
  vec4 wo;          // xyz: towards the previous vertex; w: ray length from the camera
  vec4 throughput;  // rgb: throughput of the specular chain before it
  BsdfParams bsdf;
};

// Running sums per pixel over progressive passes (k = pass, w_k = its weight).
struct AccumPixel {
  vec4 direct;     // rgb: sum of each pass's direct estimate x its light samples; w: their sum
  vec4 indirect;   // rgb: sum w_k (map integral + path-traced narrow lobes); w: sum w_k
  vec4 residual;   // rgb: sum w_k (control-variate residual); w: residual samples
  vec4 residualSq;  // rgb: sum w_k R_k^2 (R_k: pass k's residual); w: sum w_k^2 (its passes)
  vec4 albedo;     // first-hit records, as film::FilmPixel; albedo.w: passes
  vec4 normal;    // w: sum over the direct samples of their luminance squared (osr_direct)
  vec4 depth;     // xy as film::FilmPixel; z: passes' share of camera rays that saw light
                  // directly; w: sum over the direct samples of their luminance
  vec4 compositeSq;  // x: sum w_k lum(C_k)^2 (C_k: pass k's composite, osr_composite, over
                     // the passes that traced their maps); y: sum w_k; z: sum w_k^2;
                     // w: sum w_k lum(C_k)
  vec4 tracedSq;     // the same moments of what osr_residual path-traces in full each pass
                     // (narrow lobes, pixels no map covers: T_k), over every pass
  vec4 mirroredSq;   // the same moments, weighted by the pass's light samples, of the lights
                     // osr_gbuffer meets past a near-specular bounce (lights seen in mirrors:
                     // a sampled direction, so noise), over every pass
};

// Where one hemisphere map of the pass was taken (osr_maps writes it; MapTracer's host fills
// only `pixel`, which osr_maps reads back with a grid radius of 0).
struct MapPoint {
  vec4 position;  // xyz: the grid point's surface position; w: 1 valid map, 0 none
  vec4 normal;    // xyz: its shading normal (the map frame's z); w: pixel footprint (world)
  uvec4 pixel;    // x, y: the pixel it was taken at; z: 1 read from the map cache (taken
                  // elsewhere: interpolated by world distance, lib/osr_maps.glsl gatherMaps)
};

// What osr_map_project makes of one clean map: its irradiance at its own normal and elsewhere.
struct MapProjection {
  vec4 mean;    // rgb: mean radiance of the clean map (irradiance at the normal = pi mean);
                // w: the sum of its texels' luminance (the guided residual's pdf)
  vec4 sh[9];   // rgb: irradiance SH (Ramamoorthi & Hanrahan 2001) in the map's frame,
                // w of sh[0]: unused
  vec4 rowLuminance[8];  // the luminance summed over each of the map's 32 texel rows, row
                         // 4 i + j in component j of element i: osr_residual draws texels
                         // by it (lib/osr_maps.glsl sampleGatheredMaps)
};

// Per-map normalization statistics of the one-shot input (DESIGN.md "Normalization").
struct MapStats {
  vec4 meanRadiance;  // rgb: per-channel means; w: mean over all three channels
  vec4 meanDistance;  // x: mean distance (misses count as -1)
};

// The grid of the current maps: map m sits in cell (m % cellsX, m / cellsX), at a pixel of
// the cell jittered by `seed` (lib/osr_maps.glsl mapPixel); radius 0: at the pixels of their
// MapPoints.
struct MapGrid {
  uint radius;  // spacing r of the grid, pixels
  uint cellsX;  // cells (= maps) across and down
  uint cellsY;
  uint seed;    // jitter of the grid points
};

// ---- The world-space map cache (docs/osr.md "The map cache") -------------------------------
// A set-associative hash table of clean maps keyed by a world cell (a grid of the size of the
// pass's grid spacing at the point, quantized to a power of two) and the normal's dominant
// axis: slots = sets x kMapCacheWays; a set's ways are replaced least recently used first.
OSR_CONST(uint, kMapCacheWays, 4u);
OSR_CONST(uint, kMapCacheNone, 0xffffffffu);
// A cached map serves a grid point whose shading normal is this close to the map's own (its
// frame), and whose grid is at most kMapCacheSparse times finer than the map's grid was.
OSR_CONST(float, kMapCacheMinCos, 0.95f);
OSR_CONST(float, kMapCacheSparse, 1.2f);

// What a map pass does at each grid point (MapCacheRef.action). 0 is the no-cache default.
OSR_CONST(uint, kMapCacheTrace, 0u);   // traced, not stored (no cache, no slot, or lost its slot)
OSR_CONST(uint, kMapCacheReuse, 1u);   // read from the cache, not traced
OSR_CONST(uint, kMapCacheRefine, 2u);  // traced and averaged into the cached map it hit
OSR_CONST(uint, kMapCacheInsert, 3u);  // traced and stored in a free or least recently used slot

// The map cache's cells for a grid of world spacing `spacing`: cubes of side 2^level, level =
// ceil(log2(cellScale x spacing)), so a zoom by less than 2x keeps the cells. A cached map
// serves the grid points of its cell (lib/osr_map_cache.glsl keys by level); src/osr/map_cache
// bounds where those lie when it invalidates the maps near an object that moved.
OSR_OSR_FN int mapCacheCellLevel(float spacing, float cellScale) {
  return int(ceil(log2(max(spacing * cellScale, 1e-20f))));
}

struct MapCacheEntry {
  vec4 position;  // xyz: where the map was first traced; w: the grid spacing it served (world)
  vec4 normal;    // xyz: its shading normal (the map frame's z)
  uvec4 state;    // x: cell key (0: empty); y: clock of its last use; z: map passes averaged
                  // in it; w: scene generation it was traced in
};

// One per map of the pass: osr_cache_lookup writes it, the map passes and the store read it.
struct MapCacheRef {
  uint action;  // kMapCache*
  uint slot;    // the slot read, refined or claimed (kMapCacheNone: a victim is chosen later)
  uint key;     // the grid point's cell key
  uint passes;  // map passes in the slot before this one (kMapCacheRefine)
};

// Push constants, one struct per pass. `pass` is the progressive pass index (it selects the
// random streams); pixel passes cover pixels [pixelOffset, pixelOffset + pixelCount).
struct GBufferPush {
  uint pass;
  uint pixelOffset;
  uint pixelCount;
  uint cameraRays;     // camera rays per pixel that average the lights seen directly
  float directWeight;  // the direct layer's weight of this pass (its light samples per pixel)
};

struct DirectPush {
  uint pass;
  uint pixelOffset;
  uint pixelCount;
  uint lightSamples;  // per pixel; also the pass's weight in the direct layer (at least 1)
};

struct MapsPush {
  MapGrid grid;
  uint pass;
  uint mapOffset;            // first map of this chunk
  uint mapCount;             // maps in this chunk
  uint pathsPerTexel;
  uint gbufferWindowOffset;  // the pixel gGBuffer's element 0 is
};

struct MapNormalizePush {
  uint mapCount;  // maps in this chunk
};

struct MapDenoisePush {
  uint mapOffset;  // first map of this chunk (gMapClean's element 0)
  uint mapCount;   // maps in this chunk
};

struct MapProjectPush {
  uint mapOffset;  // first map of this chunk (gMapClean's element 0)
  uint mapCount;
};

struct CompositePush {
  MapGrid grid;
  uint pass;
  uint pixelOffset;
  uint pixelCount;
  uint cleanMapOffset;  // the map gMapClean's element 0 is
  uint glossySamples;   // directions drawn from a wide GGX lobe per pixel
  float passWeight;     // w_k of this pass
  float momentWeight;   // w_k where this pass traced its maps, else 0: a pass that reuses the
                        // last pass's maps repeats its composite, which is no new sample of it
};

struct ResidualPush {
  MapGrid grid;
  uint pass;
  uint pixelOffset;
  uint pixelCount;
  uint cleanMapOffset;  // the map gMapClean's element 0 is
  uint pathsPerPixel;
  float passWeight;     // w_k of this pass
  float guideShare;     // probability of drawing a path's first direction from the maps where
                        // a pixel's BSDF is diffuse (0: the BSDF's alone; docs/osr.md)
};

// The cache's passes (osr_cache_lookup, osr_cache_claim, osr_cache_store) share one struct:
// they must agree on every field for one chunk of maps.
struct MapCachePush {
  MapGrid grid;
  uint mapOffset;            // first map of this dispatch (gMapClean's element 0)
  uint mapCount;
  uint gbufferWindowOffset;  // the pixel gGBuffer's element 0 is
  uint sets;                 // slots / kMapCacheWays
  uint generation;           // entries of another generation are stale (a scene change)
  uint clock;                // map passes recorded since the cache was made (LRU time)
  uint mapPass;              // map passes since the restart: slots averaging fewer are refined
  uint phase;                // osr_cache_claim: 0 claim a slot, 1 keep only the claims won
  float cellScale;           // hash cell size in grid spacings (before rounding up to 2^k)
  uint maturePasses;         // slots averaging fewer map passes are refined too (0: no floor)
  uint _pad1, _pad2;
};

struct ResolvePush {
  uint pixelOffset;
  uint pixelCount;
  float residualBlend;  // weight of the accumulated residual (0..1); < 0: measured per pixel
  float residualNoiseWeight;  // the residual's variance in the measured blend (residualShrinkBlend)
};

// ---- Formulas shared by host and device -----------------------------------------------------

// Grid cell of pixel coordinate p for spacing r.
OSR_OSR_FN uint gridCell(uint p, uint r) { return p / r; }

// DESIGN.md normalization of one-shot radiance: log(1 + I / (10 mean)) - 0.1 (mean 0: -0.1).
OSR_OSR_FN float normalizeRadiance(float value, float mean) {
  return mean > 0.0f ? log(1.0f + max(value, 0.0f) / (10.0f * mean)) - 0.1f : -0.1f;
}
// Distance (-1 on a miss): log(1 + (z + 1) / (10 (mean + 1))) - 0.1.
OSR_OSR_FN float normalizeDistance(float z, float mean) {
  return log(1.0f + (z + 1.0f) / (10.0f * (mean + 1.0f))) - 0.1f;
}

// Interpolation weight of a map taken at screen point pg (surface xg, normal ng) for a pixel
// at screen point p (surface x, normal n): falls with screen distance (in grid spacings r),
// normal disagreement, and the distance of each point from the other's tangent plane relative
// to `scale` (the world size of r pixels there). A depth gap lowers the weight.
OSR_OSR_FN float mapWeight(vec2 p, vec2 pg, float r, vec3 x, vec3 n, vec3 xg, vec3 ng,
                           float scale) {
  vec2 d = (p - pg) / r;
  float screen = max(0.0f, 1.0f - dot(d, d) / 2.25f);  // reaches 0 at 1.5 r
  float c = max(0.0f, dot(n, ng));
  float c2 = c * c;
  float normal = c2 * c2 * c2 * c2;  // cos^8
  float plane = (abs(dot(ng, x - xg)) + abs(dot(n, xg - x))) / max(scale, 1e-12f);
  return screen * screen * normal * exp(-plane * plane);
}

// The residual blend (osr_resolve, docs/osr.md "Blending the residual in"). R-bar, the
// weighted mean of the passes' residuals R_k, is an unbiased but noisy estimate of the maps'
// error b. Its variance, from the passes' spread: (mean R_k^2 - R-bar^2) / (n_eff - 1) with
// n_eff = (sum w)^2 / sum w^2; zero (unknown) before kResidualMinPasses passes: with one
// heavy-tailed path per pixel a pass, two or three passes underestimate the spread and would
// show the residual's noise too soon.
OSR_CONST(float, kResidualMinPasses, 8.0f);
// n_eff: the passes' residuals counted as equally weighted ones (0: none).
OSR_OSR_FN float residualPasses(vec4 residualSq, float weightSum) {
  return residualSq.w > 0.0f ? weightSum * weightSum / residualSq.w : 0.0f;
}
OSR_OSR_FN bool residualVarianceKnown(vec4 residualSq, float weightSum) {
  return weightSum > 0.0f && residualPasses(residualSq, weightSum) >= kResidualMinPasses;
}
// Variance of a weighted mean of per-pass luminances from their moments (x: sum w l^2, y: sum
// w, z: sum w^2, w: sum w l): the composites' spread from one map pass to the next (the grid
// points' placement, jittered each map pass, and the maps' paths), the fully path-traced
// part's from pass to pass, or the lights seen in mirrors'. 0 before two samples; osr-bench
// osr-error measures the first two. weightedMoments: one sample's contribution to them.
OSR_OSR_FN vec4 weightedMoments(float value, float weight) {
  return weight * vec4(value * value, 1.0f, weight, value);
}
OSR_OSR_FN float varianceOfWeightedMean(vec4 moments) {
  float weightSum = moments.y;
  if (weightSum <= 0.0f || moments.z <= 0.0f) return 0.0f;
  float nEff = weightSum * weightSum / moments.z;
  if (nEff < 1.5f) return 0.0f;
  float mean = moments.w / weightSum;
  return max(moments.x / weightSum - mean * mean, 0.0f) / (nEff - 1.0f);
}
OSR_OSR_FN vec3 residualVarianceOfMean(vec4 residual, vec4 residualSq, float weightSum) {
  if (!residualVarianceKnown(residualSq, weightSum)) return vec3(0.0f);
  float nEff = residualPasses(residualSq, weightSum);
  vec3 mean = vec3(residual) / weightSum;
  vec3 second = vec3(residualSq) / weightSum;
  return max(second - mean * mean, vec3(0.0f)) / (nEff - 1.0f);
}
// Positive-part James-Stein shrinkage: over a neighbourhood, with sumSq = sum of R-bar^2
// (estimates b^2 + V) and sumVar = sum of V, the blend 1 - V / (b^2 + V) = b^2 / (b^2 + V)
// minimizes (1 - beta)^2 b^2 + beta^2 V: the residual where the maps are wrong by more than
// its noise, the noise-free maps where they are not. As passes grow V -> 0 and beta -> 1
// wherever b != 0: the estimate converges to the path tracer's. 0 while V is unknown (fewer
// than kResidualMinPasses passes). V from a few passes of heavy-tailed paths is mostly too
// low, so it is taken (1 + kResidualMarginPasses / n) times larger after n passes: a margin
// that fades, better early and late than none or a fixed one (docs/osr.md "Blending the
// residual in").
OSR_CONST(float, kResidualMarginPasses, 5.0f);
OSR_OSR_FN vec3 residualShrinkBlend(vec3 sumVar, vec3 sumSq, float passes, float noiseWeight) {
  if (passes < kResidualMinPasses) return vec3(0.0f);
  float margin = noiseWeight * (1.0f + kResidualMarginPasses / passes);
  vec3 blend = vec3(1.0f) - margin * sumVar / max(sumSq, vec3(1e-20f));
  return min(max(blend, vec3(0.0f)), vec3(1.0f));
}

OSR_NAMESPACE_END
#endif
