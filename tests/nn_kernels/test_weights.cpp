// The packed weights loader: the committed file (made by tools/weights_pack.py) loads with
// the expected layer table and training conventions (mapping, normalization), and truncated,
// corrupted, wrong-magic, wrong-version and shape-mismatched files are refused with one line
// naming the file and the problem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sys/wait.h>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "common/vk_test.h"
#include "nn_kernels/weights.h"
#include "nn_kernels/weights_format.h"

using namespace osr;

namespace {

std::vector<uint8_t> readFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

std::string writeTemp(const std::vector<uint8_t>& bytes, const std::string& name) {
  auto path = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".osrw");
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  return path.string();
}

void rechecksum(std::vector<uint8_t>& bytes) {
  uint32_t crc = nn::crc32(bytes.data() + nn::kPrefixBytes, bytes.size() - nn::kPrefixBytes);
  std::memcpy(bytes.data() + nn::kOffsetChecksum, &crc, 4);
}

// Loading `bytes` as Weights throws an InputError of one line with the file name and `problem`.
template <class Weights = nn::UNetWeights>
void expectRejected(const std::vector<uint8_t>& bytes, const std::string& name, const std::string& problem) {
  const std::string path = writeTemp(bytes, name);
  try {
    Weights::load(path);
    ADD_FAILURE() << name << ": loaded without error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(problem), std::string::npos) << "message: " << msg;
    std::printf("%s -> %s\n", name.c_str(), msg.c_str());
  }
  std::filesystem::remove(path);
}

const std::string kGood = "unet_k8.osrw";

}  // namespace

TEST(Weights, LoadsThePackedFile) {
  nn::UNetWeights w = nn::UNetWeights::load(test::dataPath(kGood));
  EXPECT_EQ(w.k, 8u);
  EXPECT_FALSE(w.halfStorage);
  ASSERT_EQ(w.convs.size(), size_t(nn::kConvCount));
  EXPECT_EQ(w.convs[0].cin, 7u);
  EXPECT_EQ(w.convs[8].cin, 64u);  // decoder0 reads the 8K concatenation
  EXPECT_TRUE(w.convs[2].batchNorm);
  EXPECT_EQ(w.convs[14].cout, 3u);
  EXPECT_EQ(w.convs[14].activation, nn::Activation::Relu);
  EXPECT_EQ(w.flopsPerMap(), 16416768.0);  // sum of 2 cin cout k^2 w^2 over the 15 convs
  EXPECT_EQ(w.mapping, nn::kMappingConcentric);
  EXPECT_EQ(w.normalization, nn::kNormalizationLogMean10);
  EXPECT_NO_THROW(w.requireConventions(nn::kMappingConcentric, nn::kNormalizationLogMean10));
  nn::UNetWeights h = nn::UNetWeights::load(test::dataPath("unet_k8_fp16.osrw"));
  EXPECT_TRUE(h.halfStorage);
  // The fp16 file holds the fp32 file's weights rounded to fp16.
  for (size_t i = 0; i < w.convs[5].weight.size(); ++i)
    ASSERT_EQ(h.convs[5].weight[i], nn::halfToFloat(nn::floatToHalf(w.convs[5].weight[i])));
}

TEST(Weights, RejectsTruncated) {
  auto bytes = readFile(test::dataPath(kGood));
  expectRejected({bytes.begin(), bytes.begin() + 20}, "truncated_prefix", "truncated");
  expectRejected({bytes.begin(), bytes.end() - 100}, "truncated_data", "truncated");
}

// A pipe blocked open() forever and a device (/dev/zero) was read until memory ran out: both
// are refused before they are opened.
TEST(Weights, RejectsDevicesAndPipesUnopened) {
  for (const std::string& path :
       {test::makeFifo("weights", "pipe.osrw"), std::string("/dev/zero")}) {
    try {
      nn::UNetWeights::load(path);
      ADD_FAILURE() << path << ": accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), path + ": not a regular file (a device, pipe or socket)");
    }
  }
}

TEST(Weights, RejectsChecksumMismatch) {
  auto bytes = readFile(test::dataPath(kGood));
  bytes[bytes.size() - 5] ^= 0x40;  // one bit of the last tensor
  expectRejected(bytes, "corrupted", "checksum");
}

TEST(Weights, RejectsWrongMagic) {
  auto bytes = readFile(test::dataPath(kGood));
  bytes[0] = 'X';
  expectRejected(bytes, "magic", "magic");
}

TEST(Weights, RejectsWrongVersion) {
  auto bytes = readFile(test::dataPath(kGood));
  uint32_t v = nn::kWeightsVersion + 1;
  std::memcpy(bytes.data() + nn::kOffsetVersion, &v, 4);
  expectRejected(bytes, "version", "version");
}

TEST(Weights, RejectsShapeMismatch) {
  auto bytes = readFile(test::dataPath(kGood));
  // Claim K=6 in the header (same length, checksum recomputed): every shape is now wrong.
  std::string text(bytes.begin(), bytes.end());
  size_t at = text.find("\"base_width\":8");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 13] = '6';
  rechecksum(bytes);
  expectRejected(bytes, "shape", "has shape 8x7x3x3, expected 6x7x3x3");
}

TEST(Weights, RejectsWrongLayer) {
  auto bytes = readFile(test::dataPath(kGood));
  std::string text(bytes.begin(), bytes.end());
  size_t at = text.find("\"decoder1.3\"");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 10] = '9';
  rechecksum(bytes);
  expectRejected(bytes, "layer", "expected 'decoder1.3'");
}

// A header naming another mapping or normalization loads, exposes it, and is refused by
// requireConventions with one line naming the file; a header without the key is malformed.
TEST(Weights, ExposesAndChecksMappingAndNormalization) {
  const auto good = readFile(test::dataPath(kGood));
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text(good.begin(), good.end());
    size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    EXPECT_EQ(from.size(), to.size());  // the header keeps its length
    std::vector<uint8_t> bytes = good;
    if (at != std::string::npos) std::copy(to.begin(), to.end(), bytes.begin() + at);
    rechecksum(bytes);
    return bytes;
  };
  struct Case {
    std::string from, to, value, problem;
  };
  const Case cases[] = {
      {"\"mapping\":\"concentric\"", "\"mapping\":\"latlong-v1\"", "latlong-v1",
       "model trained for hemisphere mapping 'latlong-v1', this renderer uses 'concentric'"},
      {"\"normalization\":\"log1p_mean10_v1\"", "\"normalization\":\"linear_v1______\"",
       "linear_v1______", "model trained for normalization 'linear_v1______'"}};
  for (const Case& c : cases) {
    const std::string path = writeTemp(replaced(c.from, c.to), "conventions");
    nn::UNetWeights w = nn::UNetWeights::load(path);
    EXPECT_EQ(c.from[1] == 'm' ? w.mapping : w.normalization, c.value);
    try {
      w.requireConventions(nn::kMappingConcentric, nn::kNormalizationLogMean10);
      ADD_FAILURE() << c.value << ": accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(path + ": " + c.problem, 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
    std::filesystem::remove(path);
  }
  expectRejected(replaced("\"mapping\":", "\"mappinx\":"), "no_mapping", "malformed header");
}

// The image denoiser's file, packed by tools/weights_pack.py from image_unet.randomize(
// ImageUNet(8), 8): its layer table, and the refusals that keep one stage's file out of another.
namespace {

const std::string kImage = "image_unet_k8.osrw";

std::vector<uint8_t> replacedIn(const std::string& file, const std::string& from, const std::string& to) {
  auto bytes = readFile(test::dataPath(file));
  std::string text(bytes.begin(), bytes.end());
  size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(from.size(), to.size());  // the header keeps its length
  if (at != std::string::npos) std::copy(to.begin(), to.end(), bytes.begin() + at);
  rechecksum(bytes);
  return bytes;
}

void expectImageRejected(const std::vector<uint8_t>& bytes, const std::string& name,
                         const std::string& problem) {
  expectRejected<nn::ImageUNetWeights>(bytes, name, problem);
}

}  // namespace

TEST(Weights, LoadsThePackedImageDenoiser) {
  nn::ImageUNetWeights w = nn::ImageUNetWeights::load(test::dataPath(kImage));
  EXPECT_EQ(w.k, 8u);
  ASSERT_EQ(w.convs.size(), size_t(nn::kImageConvCount));
  EXPECT_EQ(w.convs[0].cin, 9u);
  EXPECT_EQ(w.convs[5].cin, 48u);  // dec2.0 reads cat(up(mid), s2): 4K + 2K
  EXPECT_EQ(w.convs[7].cin, 24u);  // dec0.0 reads cat(up(dec1), s0): 2K + K
  EXPECT_EQ(w.convs[9].cout, 3u);
  EXPECT_EQ(w.convs[9].kernel, 1u);
  EXPECT_EQ(w.convs[9].activation, nn::Activation::None);
  EXPECT_EQ(w.convs[4].activation, nn::Activation::Relu);
  // 2 cin cout k^2 / 4^scale summed: 9*8*9 + 8*8*9 + (8*16*9)/4 + (16*16*9)/16 + (16*32*9)/64
  // + (48*16*9)/16 + (32*16*9)/4 + 24*8*9 + 8*8*9 + 8*3, doubled.
  EXPECT_DOUBLE_EQ(w.flopsPerPixel(), 2.0 * (648 + 576 + 288 + 144 + 72 + 432 + 1152 + 1728 + 576 + 24));
}

TEST(Weights, StagesRefuseEachOthersFiles) {
  try {
    nn::UNetWeights::load(test::dataPath(kImage));
    ADD_FAILURE() << "the map denoiser loaded an image denoiser";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), test::dataPath(kImage) +
              ": model of stage 'image_denoiser' (osr_image_unet_v1), this needs stage "
              "'map_denoiser' (osr_unet_v1)");
  }
  // The committed map file predates the "stage" key: it is a map denoiser.
  try {
    nn::ImageUNetWeights::load(test::dataPath(kGood));
    ADD_FAILURE() << "the image denoiser loaded a map denoiser";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), test::dataPath(kGood) +
              ": model of stage 'map_denoiser' (osr_unet_v1), this needs stage "
              "'image_denoiser' (osr_image_unet_v1)");
  }
}

TEST(Weights, ImageDenoiserRefusesBadFiles) {
  auto bytes = readFile(test::dataPath(kImage));
  expectImageRejected({bytes.begin(), bytes.end() - 7}, "image_truncated", "truncated");
  expectImageRejected(replacedIn(kImage, "\"osr_image_unet_v1\"", "\"osr_image_unet_v2\""),
                      "image_arch", "architecture 'osr_image_unet_v2', expected 'osr_image_unet_v1'");
  expectImageRejected(replacedIn(kImage, "\"albedo\",\"normal\"", "\"normal\",\"albedo\""),
                      "image_inputs", "model inputs (colour, normal, albedo) are not what the renderer feeds");
  expectImageRejected(replacedIn(kImage, "\"colour\",", "\"depth\", "), "image_depth",
                      "model inputs (depth, albedo, normal)");
  expectImageRejected(replacedIn(kImage, "exposure_log1p", "exposure_log2p"), "image_transform",
                      "input transform 'exposure_log2p', this renderer implements 'exposure_log1p'");
  expectImageRejected(replacedIn(kImage, "\"dec1.0\"", "\"dec1.9\""), "image_layer",
                      "layer 6 is 'dec1.9', expected 'dec1.0'");
  expectImageRejected(replacedIn(kImage, "\"base_width\":8", "\"base_width\":6"), "image_shape",
                      "tensor enc0.0.weight has shape 8x9x3x3, expected 6x9x3x3");
}

// A fresh checkpoint of each image architecture packs, and the packer refuses one whose declared
// architecture disagrees with its keys (one line, exit 2).
TEST(Weights, PackerDetectsTheArchitecture) {
  const char* py = "/usr/bin/python3";
  if (std::system((std::string(py) + " -c 'import torch' >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no torch";
  namespace fs = std::filesystem;
  const fs::path dir = test::tempDir("weights_stages");
  const std::string tools = test::sourcePath("tools");
  const std::string image = (dir / "image.pt").string(), liar = (dir / "liar.pt").string();
  const std::string kpn = (dir / "kpn.pt").string(), kpn2 = (dir / "kpn2.pt").string();
  const std::string kpn3 = (dir / "kpn3.pt").string(), kpn4 = (dir / "kpn4.pt").string();
  const std::string make =
      std::string(py) + " -c \"import sys; sys.path.insert(0, '" + tools + "'); import image_unet, torch; " +
      "m = image_unet.ImageUNet(4, 'osr_image_unet_v1'); image_unet.randomize(m, 3); " +
      "torch.save({'model': m.state_dict(), 'architecture': 'osr_image_unet_v1', 'base_width': 4, 'epoch': 7}, '" +
      image + "'); torch.save({'model': m.state_dict(), 'architecture': 'osr_unet_v1'}, '" + liar + "'); " +
      "torch.save({'model': image_unet.ImageUNet(4).state_dict()}, '" + kpn + "'); " +
      "torch.save({'model': image_unet.ImageUNet(4).state_dict(), 'architecture': 'osr_image_kpn_v2'}, '" + kpn2 +
      "'); torch.save({'model': image_unet.ImageUNet(4).state_dict(), 'architecture': 'osr_image_kpn_v3'}, '" +
      kpn3 + "'); torch.save({'model': image_unet.ImageUNet(4).state_dict(), 'architecture': 'osr_image_kpn_v4'}, '" +
      kpn4 + "')\"";
  ASSERT_EQ(std::system(make.c_str()), 0);
  const std::string packed = (dir / "image.osrw").string();
  ASSERT_EQ(std::system((std::string(py) + " " + tools + "/weights_pack.py " + image + " " + packed).c_str()), 0);
  nn::ImageUNetWeights w = nn::ImageUNetWeights::load(packed);
  EXPECT_EQ(w.k, 4u);
  EXPECT_EQ(w.convs[6].cin, 16u);
  EXPECT_FALSE(w.predictsKernels());
  // Packs a checkpoint next to it (.pt -> .osrw) and loads the packed file.
  const auto packAndLoad = [&](const std::string& checkpoint) {
    const std::string out = checkpoint.substr(0, checkpoint.size() - 3) + ".osrw";
    EXPECT_EQ(std::system((std::string(py) + " " + tools + "/weights_pack.py " + checkpoint + " " + out).c_str()), 0);
    return nn::ImageUNetWeights::load(out);
  };
  const nn::ImageUNetWeights k = packAndLoad(kpn);
  EXPECT_TRUE(k.predictsKernels());
  EXPECT_FALSE(k.guided());
  EXPECT_EQ(k.convs.back().cout, nn::kImageKpnOutChannels);
  // The guided kernels have the same weights: the checkpoint's "architecture" tells them apart.
  const nn::ImageUNetWeights k2 = packAndLoad(kpn2);
  EXPECT_TRUE(k2.predictsKernels());
  EXPECT_TRUE(k2.guided());
  EXPECT_EQ(k2.architecture, nn::kImageGuidedKpnArchitecture);
  EXPECT_FALSE(k2.filterGuided());
  const nn::ImageUNetWeights k3 = packAndLoad(kpn3);
  EXPECT_TRUE(k3.predictsKernels());
  EXPECT_TRUE(k3.guided());
  EXPECT_TRUE(k3.filterGuided());
  EXPECT_EQ(k3.architecture, nn::kImageVarianceKpnArchitecture);
  EXPECT_FALSE(k3.straddleGuided());
  const nn::ImageUNetWeights k4 = packAndLoad(kpn4);
  EXPECT_TRUE(k4.filterGuided());
  EXPECT_TRUE(k4.straddleGuided());
  EXPECT_EQ(k4.architecture, nn::kImageStraddleKpnArchitecture);
  auto text = readFile(packed);
  EXPECT_NE(std::string(text.begin(), text.end()).find("\"epoch\":7"), std::string::npos);
  const std::string err = (dir / "err.txt").string();
  const int status = std::system((std::string(py) + " " + tools + "/weights_pack.py " + liar + " " +
                                  (dir / "x.osrw").string() + " 2>" + err).c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  auto msg = readFile(err);
  const std::string all(msg.begin(), msg.end());
  EXPECT_EQ(std::count(all.begin(), all.end(), '\n'), 1) << all;
  EXPECT_NE(all.find(liar + ": checkpoint says architecture 'osr_unet_v1'"), std::string::npos) << all;
  fs::remove_all(dir);
}

TEST(Weights, Crc32AndHalfConversion) {
  const char* s = "123456789";
  EXPECT_EQ(nn::crc32(reinterpret_cast<const uint8_t*>(s), 9), 0xCBF43926u);  // the CRC-32 check value
  for (float f : {0.0f, 1.0f, -2.5f, 65504.0f, 6.103515625e-05f, 5.96e-08f, 0.1f})
    EXPECT_NEAR(nn::halfToFloat(nn::floatToHalf(f)), f, std::fabs(f) * 1e-3 + 1e-8) << f;
  EXPECT_EQ(nn::floatToHalf(1.0f), 0x3C00);
  EXPECT_EQ(nn::floatToHalf(0.1f), 0x2E66);  // round to nearest
  EXPECT_EQ(nn::floatToHalf(1e6f), 0x7C00);  // overflow to inf
}

// tools/weights_pack.py refuses checkpoints that are not the U-Net, with one line and exit 2.
TEST(Weights, PackerRejectsBadCheckpoints) {
  const char* py = "/usr/bin/python3";
  if (std::system((std::string(py) + " -c 'import torch' >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no torch";
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("osr_pack_bad_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string tools = test::sourcePath("tools");
  // Three broken state_dicts of a K=8 model: a key removed, a key added, a shape changed.
  const std::string make =
      std::string(py) + " -c \"import sys; sys.path.insert(0, '" + tools + "'); import unet, torch; " +
      "d = unet.UNet(8).state_dict(); m = dict(d); del m['decoder1.2.running_var']; " +
      "torch.save(m, '" + (dir / "missing.pt").string() + "'); e = dict(d); e['extra.weight'] = torch.zeros(1); " +
      "torch.save(e, '" + (dir / "extra.pt").string() + "'); s = dict(d); s['encoder2.4.bias'] = torch.zeros(5); " +
      "torch.save(s, '" + (dir / "shape.pt").string() + "')\"";
  ASSERT_EQ(std::system(make.c_str()), 0);
  const std::pair<const char*, const char*> cases[] = {
      {"missing", "missing keys decoder1.2.running_var"},
      {"extra", "unexpected keys extra.weight"},
      {"shape", "encoder2.4.bias has shape (5,), expected (32,)"}};
  for (auto [name, problem] : cases) {
    const std::string ckpt = (dir / (std::string(name) + ".pt")).string();
    const std::string err = (dir / "err.txt").string();
    const std::string cmd = std::string(py) + " " + tools + "/weights_pack.py " + ckpt + " " +
                            (dir / "out.osrw").string() + " 2>" + err;
    const int status = std::system(cmd.c_str());
    EXPECT_EQ(WEXITSTATUS(status), 2) << name;
    std::ifstream f(err);
    std::string all((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    EXPECT_EQ(std::count(all.begin(), all.end(), '\n'), 1) << all;
    EXPECT_NE(all.find(ckpt + ": "), std::string::npos) << all;
    EXPECT_NE(all.find(problem), std::string::npos) << all;
  }
  fs::remove_all(dir);
}

// The packer writes weights_format.h's conventions by default and a checkpoint's own
// `mapping` / `normalization` entries when it has them; the loader reads back both.
TEST(Weights, PackerWritesTheTrainingConventions) {
  const char* py = "/usr/bin/python3";
  if (std::system((std::string(py) + " -c 'import torch' >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no torch";
  namespace fs = std::filesystem;
  const fs::path dir = test::tempDir("weights_conventions");
  const std::string tools = test::sourcePath("tools");
  const std::string plain = (dir / "plain.pt").string(), other = (dir / "other.pt").string();
  const std::string make =
      std::string(py) + " -c \"import sys; sys.path.insert(0, '" + tools + "'); import unet, torch; " +
      "d = unet.UNet(4).state_dict(); torch.save(d, '" + plain + "'); " +
      "torch.save({'state_dict': d, 'mapping': 'latlong', 'normalization': 'linear'}, '" + other + "')\"";
  ASSERT_EQ(std::system(make.c_str()), 0);
  for (const std::string& ckpt : {plain, other}) {
    const std::string packed = ckpt + ".osrw";
    ASSERT_EQ(std::system((std::string(py) + " " + tools + "/weights_pack.py " + ckpt + " " + packed).c_str()), 0);
    nn::UNetWeights w = nn::UNetWeights::load(packed);
    EXPECT_EQ(w.k, 4u);
    if (ckpt == plain) {
      EXPECT_EQ(w.mapping, nn::kMappingConcentric);
      EXPECT_EQ(w.normalization, nn::kNormalizationLogMean10);
      EXPECT_NO_THROW(w.requireConventions(nn::kMappingConcentric, nn::kNormalizationLogMean10));
    } else {
      EXPECT_EQ(w.mapping, "latlong");
      EXPECT_EQ(w.normalization, "linear");
      EXPECT_THROW(w.requireConventions(nn::kMappingConcentric, nn::kNormalizationLogMean10), InputError);
    }
  }
  fs::remove_all(dir);
}
