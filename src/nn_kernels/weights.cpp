#include "nn_kernels/weights.h"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "common/error.h"
#include "common/input_file.h"
#include "nn_kernels/weights_format.h"

namespace osr::nn {

using A = Activation;
const ConvSpec kConvSpecs[kConvCount] = {
    {"encoder0.0", nullptr, 0, 1, 3, false, A::LeakyRelu},
    {"encoder0.2", nullptr, 1, 1, 3, false, A::LeakyRelu},
    {"encoder1.1", "encoder1.3", 1, 2, 3, false, A::LeakyRelu},
    {"encoder1.4", nullptr, 2, 2, 3, false, A::LeakyRelu},
    {"encoder2.1", "encoder2.3", 2, 4, 3, false, A::LeakyRelu},
    {"encoder2.4", nullptr, 4, 4, 3, false, A::LeakyRelu},
    {"encoder3.1", "encoder3.3", 4, 8, 3, false, A::LeakyRelu},
    {"encoder3.4", nullptr, 8, 4, 3, false, A::LeakyRelu},
    {"decoder0.0", "decoder0.2", 8, 4, 3, true, A::LeakyRelu},
    {"decoder0.3", nullptr, 4, 2, 3, true, A::LeakyRelu},
    {"decoder1.0", "decoder1.2", 4, 2, 3, true, A::LeakyRelu},
    {"decoder1.3", nullptr, 2, 1, 3, true, A::LeakyRelu},
    {"decoder2.0", nullptr, 2, 1, 3, true, A::LeakyRelu},
    {"decoder2.2", nullptr, 1, 1, 3, true, A::LeakyRelu},
    {"decoder2.4", nullptr, 1, 0, 1, false, A::Relu},
};

const ImageConvSpec kImageConvSpecs[kImageConvCount] = {
    {"enc0.0", 0, 1, 3, A::Relu, 0}, {"enc0.2", 1, 1, 3, A::Relu, 0},
    {"enc1.1", 1, 2, 3, A::Relu, 1}, {"enc2.1", 2, 2, 3, A::Relu, 2},
    {"mid.1", 2, 4, 3, A::Relu, 3},  {"dec2.0", 6, 2, 3, A::Relu, 2},
    {"dec1.0", 4, 2, 3, A::Relu, 1}, {"dec0.0", 3, 1, 3, A::Relu, 0},
    {"dec0.2", 1, 1, 3, A::Relu, 0}, {"dec0.4", 1, 0, 1, A::None, 0},
};

namespace {

// Resolution (width) at which each conv of kConvSpecs runs.
constexpr uint32_t kConvWidth[kConvCount] = {32, 32, 16, 16, 8, 8, 4, 4, 8, 8, 16, 16, 32, 32, 32};

uint32_t channels(uint32_t timesK, uint32_t k, uint32_t whenZero) {
  return timesK ? timesK * k : whenZero;
}

const char* activationName(A a) {
  return a == A::LeakyRelu ? "leaky_relu" : a == A::Relu ? "relu" : "none";
}

}  // namespace

uint32_t crc32(const uint8_t* data, size_t bytes) {
  static const std::array<uint32_t, 256> kTable = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int b = 0; b < 8; ++b) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < bytes; ++i) c = kTable[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

uint16_t floatToHalf(float f) {
  // Round to nearest even, with subnormals, inf and NaN (IEEE 754 binary16).
  uint32_t x;
  std::memcpy(&x, &f, 4);
  uint32_t sign = (x >> 16) & 0x8000u;
  uint32_t absx = x & 0x7FFFFFFFu;
  if (absx >= 0x7F800000u) return uint16_t(sign | 0x7C00u | (absx > 0x7F800000u ? 0x200u : 0));
  if (absx >= 0x477FF000u) return uint16_t(sign | 0x7C00u);  // rounds to >= 65520: inf
  if (absx < 0x38800000u) {  // below the smallest normal half: subnormal or zero
    float a;
    std::memcpy(&a, &absx, 4);
    return uint16_t(sign | uint32_t(std::nearbyint(a * 16777216.0f)));  // a / 2^-24
  }
  uint32_t mant = absx & 0x7FFFFFu;
  uint32_t exp = (absx >> 23) - 112;
  uint32_t h = (exp << 10) | (mant >> 13);
  uint32_t rem = mant & 0x1FFFu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1))) ++h;
  return uint16_t(sign | h);
}

float halfToFloat(uint16_t h) {
  uint32_t sign = uint32_t(h & 0x8000u) << 16;
  uint32_t exp = (h >> 10) & 0x1F, mant = h & 0x3FFu;
  float v;
  if (exp == 0) {
    v = std::ldexp(float(mant), -24);
  } else if (exp == 31) {
    uint32_t bits = 0x7F800000u | (mant << 13);
    std::memcpy(&v, &bits, 4);
  } else {
    uint32_t bits = ((exp + 112) << 23) | (mant << 13);
    std::memcpy(&v, &bits, 4);
  }
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  bits |= sign;
  std::memcpy(&v, &bits, 4);
  return v;
}

namespace {

// A convolution with random weights, uniform with variance 2 / fan_in (keeps activations O(1)
// through the layers), biases in +-0.1, `round` applied to the weights; no BatchNorm.
template <class Round>
ConvWeights randomConv(uint32_t cin, uint32_t cout, uint32_t kernel, Activation activation,
                       std::mt19937& rng, Round round) {
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  ConvWeights c;
  c.cin = cin;
  c.cout = cout;
  c.kernel = kernel;
  c.activation = activation;
  const float bound = std::sqrt(6.0f / float(cin * kernel * kernel));
  c.weight.resize(size_t(cout) * cin * kernel * kernel);
  for (float& v : c.weight) v = round(bound * uni(rng));
  c.bias.resize(cout);
  for (float& v : c.bias) v = 0.1f * uni(rng);
  c.scale.assign(cout, 1.0f);
  c.shift.assign(cout, 0.0f);
  return c;
}

}  // namespace

UNetWeights UNetWeights::random(uint32_t k, uint32_t seed, bool half) {
  UNetWeights w;
  w.k = k;
  w.halfStorage = half;
  w.source = "random(K=" + std::to_string(k) + ")";
  w.mapping = kMappingConcentric;
  w.normalization = kNormalizationLogMean10;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  auto round = [&](float v) { return half ? halfToFloat(floatToHalf(v)) : v; };
  for (const ConvSpec& s : kConvSpecs) {
    ConvWeights c = randomConv(channels(s.cinTimesK, k, kInChannels), channels(s.coutTimesK, k, kOutChannels),
                               s.kernel, s.activation, rng, round);
    c.batchNorm = s.batchNorm != nullptr;
    if (c.batchNorm)
      for (uint32_t i = 0; i < c.cout; ++i) {
        c.scale[i] = 1.0f + 0.3f * uni(rng);
        c.shift[i] = 0.2f * uni(rng);
      }
    w.convs.push_back(std::move(c));
  }
  return w;
}

ImageUNetWeights ImageUNetWeights::random(uint32_t k, uint32_t seed, const std::string& architecture) {
  ImageUNetWeights w;
  w.k = k;
  w.architecture = architecture;
  w.source = "random image U-Net (" + architecture + ", K=" + std::to_string(k) + ")";
  std::mt19937 rng(seed);
  for (const ImageConvSpec& s : kImageConvSpecs)
    w.convs.push_back(randomConv(channels(s.cinTimesK, k, kImageInChannels),
                                 channels(s.coutTimesK, k, w.outChannels()), s.kernel, s.activation, rng,
                                 [](float v) { return v; }));
  return w;
}

double ImageUNetWeights::flopsPerPixel() const {
  double flops = 0;
  for (int i = 0; i < kImageConvCount; ++i) {
    const ConvWeights& c = convs[i];
    flops += 2.0 * c.cin * c.cout * c.kernel * c.kernel / double(1u << (2 * kImageConvSpecs[i].scale));
  }
  return flops;
}

double UNetWeights::flopsPerMap() const {
  double flops = 0;
  for (int i = 0; i < kConvCount; ++i) {
    const ConvWeights& c = convs[i];
    flops += 2.0 * c.cin * c.cout * c.kernel * c.kernel * kConvWidth[i] * kConvWidth[i];
  }
  return flops;
}

namespace {

template <class T>
T readLe(std::span<const uint8_t> bytes, size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));  // the format and every host are little-endian
  return v;
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path + ": " + problem);
}

// A header value that must be a whole number in [0, max]. nlohmann's get<uint32_t>() would
// convert a float such as 1e30 with undefined behaviour, and a negative number by wrapping.
uint64_t wholeNumber(const std::string& path, const nlohmann::json& value, const std::string& what,
                     uint64_t max) {
  if (!value.is_number_unsigned() || value.get<uint64_t>() > max)
    fail(path, what + " is " + value.dump() + ", expected a whole number 0.." + std::to_string(max));
  return value.get<uint64_t>();
}

// Reads tensor `key` of layer `layer` with the expected shape into `out` as floats.
void readTensor(const std::string& path, std::span<const uint8_t> file, uint64_t dataOffset,
                uint64_t dataBytes, const nlohmann::json& layer, const char* key,
                const std::vector<uint64_t>& shape, std::vector<float>& out) {
  const std::string where = layer.value("name", std::string("?")) + "." + key;
  if (!layer.contains("tensors") || !layer["tensors"].contains(key))
    fail(path, "layer tensor " + where + " is missing");
  const nlohmann::json& t = layer["tensors"][key];
  std::vector<uint64_t> got;
  for (const nlohmann::json& d : t.at("shape"))
    got.push_back(wholeNumber(path, d, "tensor " + where + " shape", uint64_t(1) << 32));
  if (got != shape) {
    std::string g, e;
    for (auto v : got) g += (g.empty() ? "" : "x") + std::to_string(v);
    for (auto v : shape) e += (e.empty() ? "" : "x") + std::to_string(v);
    fail(path, "tensor " + where + " has shape " + g + ", expected " + e);
  }
  uint64_t count = 1;
  for (auto v : shape) count *= v;
  const std::string dtype = t.at("dtype").get<std::string>();
  const uint64_t elem = dtype == "f32" ? 4 : dtype == "f16" ? 2 : 0;
  if (!elem) fail(path, "tensor " + where + " has unknown dtype '" + dtype + "'");
  const uint64_t limit = uint64_t(1) << 40;  // a bound that keeps the checks below from wrapping
  const uint64_t offset = wholeNumber(path, t.at("offset"), "tensor " + where + " offset", limit);
  const uint64_t bytes = wholeNumber(path, t.at("bytes"), "tensor " + where + " bytes", limit);
  if (bytes != count * elem) fail(path, "tensor " + where + " byte size does not match its shape");
  if (offset % kDataAlignment) fail(path, "tensor " + where + " is not aligned");
  if (offset > dataBytes || bytes > dataBytes - offset)
    fail(path, "tensor " + where + " lies outside the data section");
  const uint8_t* p = file.data() + dataOffset + offset;
  out.resize(count);
  for (uint64_t i = 0; i < count; ++i) {
    if (elem == 4) {
      std::memcpy(&out[i], p + 4 * i, 4);
    } else {
      uint16_t h;
      std::memcpy(&h, p + 2 * i, 2);
      out[i] = halfToFloat(h);
    }
  }
}

}  // namespace

namespace {

// A packed file's checked prefix and parsed JSON header.
struct Packed {
  nlohmann::json header;
  uint64_t dataOffset = 0, dataBytes = 0;
};

std::vector<uint8_t> readWholeFile(const std::string& path) {
  if (auto problem = inputFileProblem(path)) fail(path, *problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open weights file");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Packed readPacked(std::span<const uint8_t> file, const std::string& path) {
  if (file.size() < kPrefixBytes) fail(path, "truncated: " + std::to_string(file.size()) + " bytes");
  if (std::memcmp(file.data(), kWeightsMagic, 8) != 0)
    fail(path, "not a packed U-Net weights file (bad magic)");
  const uint32_t version = readLe<uint32_t>(file, kOffsetVersion);
  if (version != kWeightsVersion)
    fail(path, "weights format version " + std::to_string(version) + ", this build reads " +
                   std::to_string(kWeightsVersion));
  Packed p;
  const uint64_t headerBytes = readLe<uint64_t>(file, kOffsetHeaderBytes);
  p.dataOffset = readLe<uint64_t>(file, kOffsetDataOffset);
  p.dataBytes = readLe<uint64_t>(file, kOffsetDataBytes);
  // Each bounded first, so that the sums below cannot wrap around.
  if (headerBytes > (1ull << 40) || p.dataOffset > (1ull << 40) || p.dataBytes > (1ull << 40) ||
      p.dataOffset < kPrefixBytes + headerBytes || p.dataOffset % kDataAlignment)
    fail(path, "corrupt prefix (header/data offsets)");
  if (file.size() < p.dataOffset + p.dataBytes)
    fail(path, "truncated: " + std::to_string(file.size()) + " bytes, expected " +
                   std::to_string(p.dataOffset + p.dataBytes));
  if (file.size() > p.dataOffset + p.dataBytes) fail(path, "trailing bytes after the data section");
  const uint32_t stored = readLe<uint32_t>(file, kOffsetChecksum);
  const uint32_t actual = crc32(file.data() + kPrefixBytes, file.size() - kPrefixBytes);
  if (stored != actual) fail(path, "checksum mismatch (file corrupted)");
  try {
    p.header = nlohmann::json::parse(file.begin() + kPrefixBytes,
                                     file.begin() + kPrefixBytes + headerBytes);
  } catch (const std::exception& e) {
    fail(path, std::string("header is not valid JSON: ") + e.what());
  }
  return p;
}

// Refuses a file made for another stage, then one of another architecture.
void requireStage(const std::string& path, const nlohmann::json& header, const char* stage,
                  const char* architecture) {
  const std::string got = header.value("stage", std::string(kStageMapDenoiser));
  const std::string arch = header.at("architecture").get<std::string>();
  if (got != stage)
    fail(path, "model of stage '" + got + "' (" + arch + "), this needs stage '" + stage + "' (" +
                   architecture + ")");
  if (arch != architecture)
    fail(path, "architecture '" + arch + "', expected '" + architecture + "'");
}

uint32_t readBaseWidth(const std::string& path, const nlohmann::json& header) {
  const uint64_t k = wholeNumber(path, header.at("base_width"), "base width K", 1u << 30);
  if (k == 0 || k > 1024) fail(path, "base width K=" + std::to_string(k) + " is not in 1..1024");
  return uint32_t(k);
}

// Layer `i` of the table: its name, activation and tensors against the expected shape.
ConvWeights readConv(const std::string& path, std::span<const uint8_t> file, const Packed& p,
                     int i, const char* name, uint32_t cin, uint32_t cout, uint32_t kernel,
                     Activation activation, bool batchNorm) {
  const nlohmann::json& l = p.header.at("layers")[i];
  if (l.at("name").get<std::string>() != name)
    fail(path, "layer " + std::to_string(i) + " is '" + l["name"].get<std::string>() +
                   "', expected '" + name + "'");
  ConvWeights c;
  c.cin = cin;
  c.cout = cout;
  c.kernel = kernel;
  c.activation = activation;
  c.batchNorm = batchNorm;
  if (l.at("activation").get<std::string>() != activationName(activation))
    fail(path, std::string("layer ") + name + " has activation " + l["activation"].dump());
  if (l.contains("slope")) {
    // Checked as a double: a value beyond float's range would convert with undefined behaviour.
    const nlohmann::json& slope = l.at("slope");
    if (!slope.is_number() || !(std::fabs(slope.get<double>()) <= 1e6))
      fail(path, std::string("layer ") + name + " has slope " + slope.dump());
    c.slope = slope.get<float>();
  }
  if (l.value("batchnorm", false) != batchNorm)
    fail(path, std::string("layer ") + name + " BatchNorm presence does not match");
  readTensor(path, file, p.dataOffset, p.dataBytes, l, "weight", {cout, cin, kernel, kernel}, c.weight);
  readTensor(path, file, p.dataOffset, p.dataBytes, l, "bias", {cout}, c.bias);
  if (batchNorm) {
    readTensor(path, file, p.dataOffset, p.dataBytes, l, "bn_scale", {cout}, c.scale);
    readTensor(path, file, p.dataOffset, p.dataBytes, l, "bn_shift", {cout}, c.shift);
  } else {
    c.scale.assign(cout, 1.0f);
    c.shift.assign(cout, 0.0f);
  }
  return c;
}

// A weights object of type W from a packed file: `read(packed, w)` fills it from the header,
// whose missing keys or wrong types become one "malformed header" line.
template <class W, class Read>
W parseWith(std::span<const uint8_t> file, const std::string& path, Read read) {
  const Packed p = readPacked(file, path);
  W w;
  w.source = path;
  try {
    read(p, w);
  } catch (const nlohmann::json::exception& e) {
    fail(path, std::string("malformed header: ") + e.what());
  }
  return w;
}

void requireLayerCount(const std::string& path, const nlohmann::json& header, int count) {
  const nlohmann::json& layers = header.at("layers");
  if (!layers.is_array() || layers.size() != size_t(count))
    fail(path, "layer table has " + std::to_string(layers.size()) + " layers, expected " +
                   std::to_string(count));
}

}  // namespace

UNetWeights UNetWeights::load(const std::string& path) { return parse(readWholeFile(path), path); }

UNetWeights UNetWeights::parse(std::span<const uint8_t> file, const std::string& path) {
  return parseWith<UNetWeights>(file, path, [&](const Packed& p, UNetWeights& w) {
    const nlohmann::json& header = p.header;
    requireStage(path, header, kStageMapDenoiser, kArchitecture);
    w.k = readBaseWidth(path, header);
    if (wholeNumber(path, header.at("map_size"), "map size", 1u << 30) != kMapSize)
      fail(path, "map size " + header.at("map_size").dump() + ", expected " + std::to_string(kMapSize));
    w.halfStorage = header.at("dtype").get<std::string>() == "f16";
    w.mapping = header.at("mapping").get<std::string>();
    w.normalization = header.at("normalization").get<std::string>();
    requireLayerCount(path, header, kConvCount);
    for (int i = 0; i < kConvCount; ++i) {
      const ConvSpec& s = kConvSpecs[i];
      w.convs.push_back(readConv(path, file, p, i, s.name, channels(s.cinTimesK, w.k, kInChannels),
                                 channels(s.coutTimesK, w.k, kOutChannels), s.kernel, s.activation,
                                 s.batchNorm != nullptr));
    }
  });
}

ImageUNetWeights ImageUNetWeights::load(const std::string& path) {
  return parse(readWholeFile(path), path);
}

ImageUNetWeights ImageUNetWeights::parse(std::span<const uint8_t> file, const std::string& path) {
  return parseWith<ImageUNetWeights>(file, path, [&](const Packed& p, ImageUNetWeights& w) {
    const nlohmann::json& header = p.header;
    // Any of the image architectures; requireStage names the file's when it is none.
    const std::string declared = header.value("architecture", std::string());
    w.architecture = declared == kImageStraddleKpnArchitecture   ? kImageStraddleKpnArchitecture
                     : declared == kImageVarianceKpnArchitecture ? kImageVarianceKpnArchitecture
                     : declared == kImageGuidedKpnArchitecture ? kImageGuidedKpnArchitecture
                     : declared == kImageKpnArchitecture       ? kImageKpnArchitecture
                                                               : kImageArchitecture;
    requireStage(path, header, kStageImageDenoiser, w.architecture.c_str());
    w.k = readBaseWidth(path, header);
    // The renderer feeds the first-hit colour, albedo and normal; a model asking for anything
    // else (or another order or transform) cannot be fed by any mode.
    const std::vector<std::string> want = {kInputColour, kInputAlbedo, kInputNormal};
    const auto inputs = header.at("inputs").get<std::vector<std::string>>();
    if (inputs != want) {
      std::string list;
      for (const auto& s : inputs) list += (list.empty() ? "" : ", ") + s;
      fail(path, "model inputs (" + list + ") are not what the renderer feeds (colour, albedo, normal)");
    }
    const std::string transform = header.at("input_transform").get<std::string>();
    if (transform != kInputTransformExposureLog1p)
      fail(path, "input transform '" + transform + "', this renderer implements '" +
                     kInputTransformExposureLog1p + "'");
    const uint64_t in = wholeNumber(path, header.at("in_channels"), "in_channels", 1u << 30);
    const uint64_t out = wholeNumber(path, header.at("out_channels"), "out_channels", 1u << 30);
    if (in != kImageInChannels || out != w.outChannels())
      fail(path, "channels " + std::to_string(in) + " -> " + std::to_string(out) + ", expected " +
                     std::to_string(kImageInChannels) + " -> " + std::to_string(w.outChannels()));
    requireLayerCount(path, header, kImageConvCount);
    for (int i = 0; i < kImageConvCount; ++i) {
      const ImageConvSpec& s = kImageConvSpecs[i];
      w.convs.push_back(readConv(path, file, p, i, s.name, channels(s.cinTimesK, w.k, kImageInChannels),
                                 channels(s.coutTimesK, w.k, w.outChannels()), s.kernel, s.activation, false));
    }
  });
}

void UNetWeights::requireConventions(std::string_view wantMapping,
                                     std::string_view wantNormalization) const {
  if (mapping != wantMapping)
    throw InputError(source + ": model trained for hemisphere mapping '" + mapping +
                     "', this renderer uses '" + std::string(wantMapping) + "'");
  if (normalization != wantNormalization)
    throw InputError(source + ": model trained for normalization '" + normalization +
                     "', this renderer uses '" + std::string(wantNormalization) + "'");
}

}  // namespace osr::nn
