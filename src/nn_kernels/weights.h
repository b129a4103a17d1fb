// U-Net weights in memory: the layer table of the seed's network for base width K (the graph
// the engine runs) and the loader of packed files (weights_format.h). Values are held as
// float; a file stored in fp16 keeps `halfStorage`, and since fp16 -> float -> fp16 is exact
// the device copy is bit-identical to the file.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "nn_kernels/weights_format.h"

namespace osr::nn {

enum class Activation : uint32_t { None = 0, LeakyRelu = 1, Relu = 2 };

// One convolution of the network and the fused epilogue of DESIGN.md "Network".
struct ConvSpec {
  const char* name;       // PyTorch state_dict prefix of the conv, e.g. "decoder1.0"
  const char* batchNorm;  // prefix of the BatchNorm after its activation, or nullptr
  uint32_t cinTimesK;     // input channels = cinTimesK * K, or kInChannels when 0
  uint32_t coutTimesK;    // output channels = coutTimesK * K, or kOutChannels when 0
  uint32_t kernel;        // 3 or 1
  bool transposed;        // ConvTranspose2d in PyTorch (the packer has flipped it)
  Activation activation;
};

// The seed's U-Net (thesis Appendix B) in execution order.
inline constexpr int kConvCount = 15;
extern const ConvSpec kConvSpecs[kConvCount];

struct ConvWeights {
  uint32_t cin = 0, cout = 0, kernel = 3;
  Activation activation = Activation::LeakyRelu;
  float slope = 0.2f;
  bool batchNorm = false;
  std::vector<float> weight;  // [cout][cin][kernel][kernel], as a plain (not transposed) conv
  std::vector<float> bias;    // [cout]
  std::vector<float> scale;   // [cout], 1 without BatchNorm
  std::vector<float> shift;   // [cout], 0 without BatchNorm
};

struct UNetWeights {
  uint32_t k = 0;
  bool halfStorage = false;
  std::string source;  // file name, for messages
  // The header's conventions the model was trained for (weights_format.h kMapping*,
  // kNormalization*): a pass feeding it maps must implement both.
  std::string mapping, normalization;
  std::vector<ConvWeights> convs;  // kConvSpecs order

  // Random weights (He-like scale, BatchNorm scale near 1) for tests and benchmarks. With
  // `half` the values are rounded to fp16 so device and CPU see the same numbers.
  static UNetWeights random(uint32_t k, uint32_t seed, bool half = false);
  // Throws InputError "<path>: <problem>" on any mismatch with weights_format.h.
  static UNetWeights load(const std::string& path);
  // The same from the bytes of a packed file (e.g. the model built into the executable);
  // `source` names it in messages.
  static UNetWeights parse(std::span<const uint8_t> bytes, const std::string& source);
  // Throws InputError "<source>: <problem>" unless the model was trained for this mapping and
  // normalization, so that a caller refuses a model made for other maps.
  void requireConventions(std::string_view mapping, std::string_view normalization) const;
  // Floating-point operations of one 32x32 map (2 per multiply-add).
  double flopsPerMap() const;
};

// The image denoiser (stage "image_denoiser", architecture "osr_image_kpn_v1" or
// "osr_image_unet_v1", tools/image_unet.py LAYERS) in execution order: plain convolutions with ReLU, the last a 1x1
// without activation. `scale` is the resolution it runs at as a power of two (0 full, 3 1/8).
struct ImageConvSpec {
  const char* name;
  uint32_t cinTimesK;   // input channels = cinTimesK * K, or kImageInChannels when 0
  uint32_t coutTimesK;  // output channels = coutTimesK * K, or the model's outputs when 0
  uint32_t kernel;
  Activation activation;
  uint32_t scale;
};
inline constexpr int kImageConvCount = 10;
extern const ImageConvSpec kImageConvSpecs[kImageConvCount];

struct ImageUNetWeights {
  uint32_t k = 0;
  // kImageStraddleKpnArchitecture, kImageVarianceKpnArchitecture, kImageGuidedKpnArchitecture
  // or kImageKpnArchitecture (kernel logits out; the first three's kernels are multiplied by
  // fixed normal and depth factors, the first two's also by the a-trous filter's luminance and
  // B3-spline factors, the first's normal factor compares pixels on edges by their mean
  // normals) or kImageArchitecture (colour out).
  std::string architecture = kImageKpnArchitecture;
  std::string source;
  std::vector<ConvWeights> convs;  // kImageConvSpecs order, no BatchNorm

  bool predictsKernels() const { return architecture == kImageKpnArchitecture || guided(); }
  // Reads the depth: the kernels have the normal and depth factors.
  bool guided() const { return architecture == kImageGuidedKpnArchitecture || filterGuided(); }
  // Reads the film's variance: the kernels also have the a-trous filter's factors.
  bool filterGuided() const { return architecture == kImageVarianceKpnArchitecture || straddleGuided(); }
  // Compares pixels that straddle an edge by their mean normals, as the a-trous filter does.
  bool straddleGuided() const { return architecture == kImageStraddleKpnArchitecture; }
  uint32_t outChannels() const { return predictsKernels() ? kImageKpnOutChannels : kOutChannels; }
  // Random weights (uniform, variance 2 / fan_in; biases in +-0.1) for tests and benchmarks.
  static ImageUNetWeights random(uint32_t k, uint32_t seed,
                                 const std::string& architecture = kImageKpnArchitecture);
  // Throw InputError "<source>: <problem>": a file of another stage or architecture, inputs
  // other than colour, albedo, normal with the exposure_log1p transform, or any mismatch
  // with weights_format.h.
  static ImageUNetWeights load(const std::string& path);
  static ImageUNetWeights parse(std::span<const uint8_t> bytes, const std::string& source);
  // Floating-point operations per full-resolution pixel (2 per multiply-add).
  double flopsPerPixel() const;
};

uint32_t crc32(const uint8_t* data, size_t bytes);
uint16_t floatToHalf(float f);
float halfToFloat(uint16_t h);

}  // namespace osr::nn
