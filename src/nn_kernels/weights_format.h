// The packed U-Net weights file, byte level (docs/weights_format.md describes it in prose).
// This header is the format's only definition: tools/weights_pack.py parses its
// `inline constexpr` lines (name = integer or string literal), so do not add other syntax to
// those lines.
//
//   offset  size  field (little-endian)
//   0       8     kWeightsMagic (ASCII, no terminator)
//   8       4     u32 version = kWeightsVersion
//   12      4     u32 CRC-32 (zlib polynomial) of every byte from kPrefixBytes to the end
//   16      8     u64 header bytes: UTF-8 JSON at offset kPrefixBytes
//   24      8     u64 data offset (multiple of kDataAlignment, after the header)
//   32      8     u64 data bytes (file size = data offset + data bytes)
//   40            JSON header, zero padding, tensor data (each tensor kDataAlignment-aligned)
#pragma once
#include <cstdint>

namespace osr::nn {

inline constexpr char kWeightsMagic[] = "OSRUNETW";
inline constexpr uint32_t kWeightsVersion = 1;
inline constexpr uint32_t kOffsetVersion = 8;
inline constexpr uint32_t kOffsetChecksum = 12;
inline constexpr uint32_t kOffsetHeaderBytes = 16;
inline constexpr uint32_t kOffsetDataOffset = 24;
inline constexpr uint32_t kOffsetDataBytes = 32;
inline constexpr uint32_t kPrefixBytes = 40;
inline constexpr uint32_t kDataAlignment = 64;
// The header's "stage" names what a file's network is for; a file without the key is a map
// denoiser (files packed before stages existed). Each stage has one architecture.
inline constexpr char kStageMapDenoiser[] = "map_denoiser";
inline constexpr char kStageImageDenoiser[] = "image_denoiser";
inline constexpr char kArchitecture[] = "osr_unet_v1";
inline constexpr uint32_t kMapSize = 32;
inline constexpr uint32_t kInChannels = 7;
inline constexpr uint32_t kOutChannels = 3;
// Header values naming the conventions a model was trained for, as this build implements
// them: the hemisphere mapping (DESIGN.md "Hemisphere maps": cosine-weighted concentric) and
// the input/target normalization (DESIGN.md "Normalization": log(1 + x / (10 mean)) - 0.1).
inline constexpr char kMappingConcentric[] = "concentric";
inline constexpr char kNormalizationLogMean10[] = "log1p_mean10_v1";
// The same input; the output is radiance 10 m (exp(y) - 1) as predicted, m the one-shot map's
// mean, instead of rescaled to the one-shot channel means (docs/training.md: measured better,
// since a 1-path map's mean is its noisiest statistic).
inline constexpr char kNormalizationLogMean10Absolute[] = "log1p_mean10_abs_v1";
// The image denoiser (tools/image_unet.py): colour, albedo and normal in (3 channels each, in
// this order), colour out; the colour goes in as log1p(e * colour), e the image's exposure
// scale, and comes out as expm1(max(y, 0)) / e. Images are padded to multiples of 8.
inline constexpr char kImageArchitecture[] = "osr_image_unet_v1";
// The kernel-predicting image denoiser: the same network and input, 100 outputs, the logits of
// four 5 x 5 kernels applied in turn to the albedo-demodulated colour (shared/denoise.h).
inline constexpr char kImageKpnArchitecture[] = "osr_image_kpn_v1";
// The same network, input and outputs; each kernel tap's weight is multiplied by fixed normal
// and depth edge-stopping factors (image_unet.guide_logits), so it also reads the depth.
inline constexpr char kImageGuidedKpnArchitecture[] = "osr_image_kpn_v2";
// The same network, input and outputs; each tap's weight is also multiplied by the a-trous
// filter's B3-spline weight and its luminance factor, scaled by each pixel's variance, which
// every level carries on (image_unet.filter_logits): the kernels start as the filter, so it
// also reads the depth and the film's variance.
inline constexpr char kImageVarianceKpnArchitecture[] = "osr_image_kpn_v3";
// v3 with the normal factor of a pixel that straddles an edge (its mean normal shorter than
// kGuideStraddleLength, shared/denoise.h) taken on the mean normals, as the a-trous filter's.
inline constexpr char kImageStraddleKpnArchitecture[] = "osr_image_kpn_v4";
inline constexpr uint32_t kImageKpnOutChannels = 100;
inline constexpr uint32_t kImageInChannels = 9;
inline constexpr uint32_t kImageMultiple = 8;
inline constexpr char kInputTransformExposureLog1p[] = "exposure_log1p";
inline constexpr char kInputColour[] = "colour";
inline constexpr char kInputAlbedo[] = "albedo";
inline constexpr char kInputNormal[] = "normal";

}  // namespace osr::nn
