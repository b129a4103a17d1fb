// The image denoisers (src/denoise, docs/denoise.md): the learned network's input and output
// passes and exposure reduction, and the edge-aware a-trous filter, shared by GLSL and C++.
// Their image layers are one vec4 per pixel, row-major, row 0 at the top:
//   colour: rgb the film's combined colour; w: variance of the pixel's luminance estimate
//   albedo: rgb the first-hit albedo; w: the first hit's view-axis depth (0: no hit)
//   normal: xyz the first-hit normal (world, facing the camera); w: the share of the pixel's
//     camera rays that saw light directly (render::FilmLayers::light). Both denoisers keep such
//     a pixel as it is and out of every other pixel's average: a lamp or the sky is not noise,
//     and a neighbour's weight on a light 1000 times brighter is a halo.
// Network tensors (src/nn_kernels/image_unet.h) are fp32 NCHW tiles of the padded image.
#ifndef OSR_SHARED_DENOISE_H
#define OSR_SHARED_DENOISE_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(denoise)

OSR_CONST(uint, kDenoiseWorkgroup, 64);  // exposure reduction: lanes per workgroup
OSR_CONST(uint, kDenoiseTile, 8);        // per-pixel passes: 8 x 8 pixels per workgroup

OSR_CONST(uint, kBindingColour, 0);
OSR_CONST(uint, kBindingAlbedo, 1);
OSR_CONST(uint, kBindingNormal, 2);
OSR_CONST(uint, kBindingExposure, 3);  // ExposureSums (exposure: partial sums, then the total)
OSR_CONST(uint, kBindingTensor, 4);    // input pass: writes the tile's input; output: reads y
OSR_CONST(uint, kBindingOut, 5);       // output pass, a-trous, convergence: vec4 per pixel
OSR_CONST(uint, kBindingDenoised, 6);  // convergence: the network's or the filter's colour
OSR_CONST(uint, kDenoiseBindingCount, 7);

// Exposure (image_unet.image_exposure): sum of log(1e-4 + luminance) and the count over pixels
// of the padded image with luminance > 0. Stage 0: one partial per workgroup; stage 1 (one
// workgroup): the total and e = 0.18 / exp(sum / count), or 1 when count is 0.
OSR_CONST(uint, kSpecExposureStage, 0);
OSR_CONST(uint, kExposurePartials, 256);  // workgroups of stage 0
OSR_CONST(float, kExposureKey, 0.18);
struct ExposureSums {
  float logSum;
  uint count;
  float exposure;  // e, valid after stage 1
  uint _pad0;
};

// Geometry of one dispatch. Image: width x height, padded (repeating the last row and
// column) to paddedWidth x paddedHeight, multiples of 8. Tile: tileWidth x tileHeight pixels
// of the padded image at (tileX, tileY); core: the part of the tile the output pass writes,
// [coreX0, coreX1) x [coreY0, coreY1) in image pixels.
struct DenoisePush {
  uint width;
  uint height;
  uint paddedWidth;
  uint paddedHeight;
  uint tileX;
  uint tileY;
  uint tileWidth;
  uint tileHeight;
  uint coreX0;
  uint coreY0;
  uint coreX1;
  uint coreY1;
  uint step;      // a-trous, kernels: the tap spacing of this iteration (1, 2, 4, 8, 16)
  float sigmaLuminance;  // a-trous: luminance edge-stopping scale (SVGF sigma_l)
  float sigmaNormal;     // a-trous: normal exponent (SVGF sigma_n)
  float sigmaDepth;      // a-trous: depth edge-stopping scale (SVGF sigma_z)
  uint samples;          // convergence: the film's samples per pixel
  uint _pad0;
  uint _pad1;
  uint _pad2;
};

// a-trous iterations: the first demodulates (colour / albedo), the last re-modulates.
OSR_CONST(uint, kSpecAtrousFirst, 0);
OSR_CONST(uint, kSpecAtrousLast, 1);

// The kernel-predicting network's kernels (tools/image_unet.py apply_kernels): kKernelLevels
// levels of kKernelSize x kKernelSize taps, 1, 2, 4, 8 pixels apart, on colour demodulated by
// the albedo (floored at kKernelDemodulateMin, or 1 where its luminance is below that). The
// first level demodulates, the last re-modulates.
OSR_CONST(uint, kKernelLevels, 4);
OSR_CONST(uint, kKernelSize, 5);
OSR_CONST(uint, kKernelTaps, 25);
OSR_CONST(float, kKernelDemodulateMin, 0.01);
OSR_CONST(uint, kSpecKernelFirst, 0);
OSR_CONST(uint, kSpecKernelLast, 1);
// osr_image_kpn_v2 (image_unet.guide_logits): each tap's weight times the fixed edge-stopping
// factors of the a-trous filter, max(cos, kGuideCosMin)^kGuideSigmaNormal between the unit
// normals and exp(-|z_p - z_q| / (kGuideSigmaDepth |grad z_p| |p - q| + kGuideDepthFloor z_p)),
// |grad z| from the smaller one-sided difference per axis (kGuideSlopeNone past the edge);
// a miss (depth 0) only with misses. Added to the logits as their logarithm.
OSR_CONST(uint, kSpecKernelGuided, 2);
OSR_CONST(float, kGuideSigmaNormal, 128.0);
OSR_CONST(float, kGuideSigmaDepth, 1.0);
OSR_CONST(float, kGuideDepthFloor, 1e-3);
OSR_CONST(float, kGuideCosMin, 1e-30);
OSR_CONST(float, kGuideSlopeNone, 1e30);
// kKernelFactorsStraddle (osr_image_kpn_v4) and the a-trous filter: where a pixel's film normal
// (the mean over its samples) is shorter than kGuideStraddleLength, it straddles an edge, and
// its normal factor is exp(-kGuideStraddleSigma |n_p - n_q|^2) on the mean normals
// (lib/film_guides.glsl normalLogFactor).
OSR_CONST(float, kGuideStraddleLength, 0.9);
OSR_CONST(float, kGuideStraddleSigma, 16.0);
// The value of kSpecKernelGuided: what each tap's weight is multiplied by besides the
// network's. kKernelFactorsFilter (osr_image_kpn_v3, image_unet.filter_logits): also the
// a-trous filter's B3-spline weight h_i h_j and exp(-|l_p - l_q| / (kFilterSigmaLuminance
// sqrt(v_p) + kFilterVarianceFloor)), l the luminance of the level's colour (linear: v3
// averages exposed, demodulated colour, as the filter does) and v_p its variance (the film's,
// demodulated and exposed, passed on by each level as the sum of squared weights times the
// taps' variances) blurred 3 x 3. kKernelFactorsStraddle (osr_image_kpn_v4): those of
// kKernelFactorsFilter, the normal factor of a pixel on an edge as the a-trous filter's.
OSR_CONST(uint, kKernelFactorsNone, 0);
OSR_CONST(uint, kKernelFactorsGeometry, 1);
OSR_CONST(uint, kKernelFactorsFilter, 2);
OSR_CONST(uint, kKernelFactorsStraddle, 3);
OSR_CONST(float, kFilterSigmaLuminance, 4.0);
OSR_CONST(float, kFilterVarianceFloor, 1e-6);

// Convergence, in two passes. First (denoise_bias.comp) the denoised colour d gains the film's
// mean gap from it, m = sum(w (x - d)) / sum(w) over the (2 kBiasRadius + 1)^2 pixels around
// (w below), times lambda = clamp(1 - k sum(w^2 v) / (sum(w)^2 l_m^2), 0, 1), the positive-part
// James-Stein rule on the mean (v the film's variance of the luminance, l_m the mean gap's
// luminance, k as below with kBiasNoiseScale): a bias spread along a face, as light from the
// next face into a band beside their edge, is measured with a 1 / sum(w) share of one pixel's
// noise. Then (denoise_converge.comp) the result, again called d, moves back towards the film's
// colour x by lambda = clamp(1 - k sum(w v) / sum(w (l_x - l_d)^2), 0, 1), sums over the
// (2 kConvergeRadius + 1)^2 pixels around, l the luminance, v the film's variance of it and
// w = max(exp(-kConvergeNormalSigma |n_p - n_q|^2), kConvergeWeightFloor) on the film's mean
// normals: 1 on the pixel's own face, little across an edge and between pixels along one whose
// mixes of the two faces differ, so that an edge's bias is not diluted by its faces' noise, nor
// do the faces beside it return to the film for it. The floor keeps some neighbours in every
// window: a pixel left alone with its own heavy-tailed variance (small lamps' light) returns to
// the film by chance. The positive-part James-Stein rule keeps d where the gap is what
// the film's noise explains and returns to x where it is more (the denoiser's bias).
// k = 1 + kConvergeNoiseScale sqrt(mean(v)) / max(mean(l_d), 1e-4) (means weighted by w), the
// film's relative standard error over the window: where few paths carry most of the light
// (small lamps), the variance of a few samples is a heavy-tailed estimate and a gap of several
// of its standard deviations is still noise. A variance of 0 (unknown, or every sample dark)
// counts as l_d^2 / samples, one sample's worth of the denoised level; pixels that saw light
// directly are left out of the sums, as the denoisers leave them out of their averages. The
// gap is the luminance's: a bias in colour alone is not seen. Films of fewer than
// kConvergeMinSamples samples per pixel are left as denoised.
OSR_CONST(int, kConvergeRadius, 1);
OSR_CONST(float, kConvergeNoiseScale, 8.0);
OSR_CONST(float, kConvergeNormalSigma, 256.0);
OSR_CONST(float, kConvergeWeightFloor, 0.1);
OSR_CONST(uint, kConvergeMinSamples, 64);
OSR_CONST(int, kBiasRadius, 2);
OSR_CONST(float, kBiasNoiseScale, 16.0);

OSR_NAMESPACE_END
#endif
