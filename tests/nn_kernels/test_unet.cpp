// The whole U-Net on the device against (1) the CPU twin with random weights at K=16 and
// K=64, fp32 and fp16; (2) PyTorch golden files made by tools/weights_pack.py --golden and
// committed (K=8, 3 maps); (3) when /usr/bin/python3 has torch, a fresh random PyTorch model
// packed and run end to end. Also: chunking gives the same result as one chunk, and layers
// with different LeakyReLU slopes keep their own.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "common/vk_test.h"
#include "nn_kernels/unet.h"
#include "nn_test_util.h"

using namespace osr;

namespace {

constexpr size_t kInMap = 7 * 32 * 32, kOutMap = 3 * 32 * 32;

std::vector<float> runGpu(const nn::UNetWeights& w, const std::vector<float>& maps, uint32_t n,
                          const nn::UNetOptions& options = {}) {
  auto& ctx = test::context();
  nn::UNet net(ctx, w, options);
  vk::Buffer in(ctx, maps.size() * 4, vk::MemoryUse::DeviceLocal, "unet test in");
  in.uploadVector(maps);
  vk::Buffer out(ctx, n * kOutMap * 4, vk::MemoryUse::DeviceLocal, "unet test out");
  ctx.submitAndWait([&](VkCommandBuffer cmd) { net.record(cmd, in, 0, out, 0, n); });
  return out.downloadVector<float>(n * kOutMap);
}

std::vector<float> readFloats(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  EXPECT_TRUE(f.good()) << path;
  std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::vector<float> v(bytes.size() / 4);
  std::memcpy(v.data(), bytes.data(), v.size() * 4);
  return v;
}

void compareWithCpu(uint32_t k, uint32_t n, bool half, double tol) {
  nn::UNetWeights w = nn::UNetWeights::random(k, 100 + k, half);
  nn::Tensor maps = test::randomTensor(n, 7, 32, 32, k);
  nn::Tensor ref = nn::unetCpu(w, maps);
  nn::UNetOptions opt;
  opt.half = half;
  std::vector<float> got = runGpu(w, maps.data, n, opt);
  const double err = test::relError(got, ref.data);
  std::printf("K=%u n=%u %s: max rel err %.3g (max |ref| %.3g)\n", k, n, half ? "fp16" : "fp32", err,
              test::maxAbs(ref.data));
  EXPECT_GT(test::maxAbs(ref.data), 0.0) << "degenerate reference (all zero after the ReLU)";
  EXPECT_LE(err, tol) << "K=" << k << " n=" << n << " half=" << half;
}

}  // namespace

TEST(UNet, RandomWeightsK16MatchesCpu) { compareWithCpu(16, 3, false, 1e-4); }
TEST(UNet, RandomWeightsK64MatchesCpu) { compareWithCpu(64, 1, false, 1e-4); }
TEST(UNet, OddBaseWidthMatchesCpu) { compareWithCpu(5, 3, false, 1e-4); }

// fp16 storage of weights and activations, fp32 arithmetic: stated bound 1e-2 relative
// (each of 15 layers rounds its output to 2^-11 relative; measured about 2e-3).
TEST(UNet, HalfStorageK16WithinBound) { compareWithCpu(16, 3, true, 1e-2); }

// Layers whose passes could be shared (same shape class, e.g. decoder2.0 and decoder2.2) but
// whose LeakyReLU slopes differ must each keep their own slope: a model may be trained with
// any per-layer slope, and the packed header carries one per layer.
TEST(UNet, LayersWithDifferentSlopesMatchCpu) {
  nn::UNetWeights w = nn::UNetWeights::random(8, 31);
  for (size_t i = 0; i < w.convs.size(); ++i) w.convs[i].slope = 0.05f + 0.04f * float(i);
  const uint32_t n = 2;
  nn::Tensor maps = test::randomTensor(n, 7, 32, 32, 17);
  nn::Tensor ref = nn::unetCpu(w, maps);
  const double err = test::relError(runGpu(w, maps.data, n), ref.data);
  std::printf("K=8 per-layer slopes: max rel err %.3g\n", err);
  EXPECT_GT(test::maxAbs(ref.data), 0.0);
  EXPECT_LE(err, 1e-4);
}

TEST(UNet, ChunksGiveTheSameResult) {
  nn::UNetWeights w = nn::UNetWeights::random(8, 5);
  const uint32_t n = 5;
  nn::Tensor maps = test::randomTensor(n, 7, 32, 32, 9);
  nn::UNetOptions small;
  small.maxChunk = 2;  // chunks of 2, 2, 1
  EXPECT_EQ(runGpu(w, maps.data, n, small), runGpu(w, maps.data, n));
}

TEST(UNet, MatchesPyTorchGoldenFp32) {
  nn::UNetWeights w = nn::UNetWeights::load(test::dataPath("unet_k8.osrw"));
  std::vector<float> in = readFloats(test::dataPath("unet_k8_golden/input.f32"));
  std::vector<float> want = readFloats(test::dataPath("unet_k8_golden/output.f32"));
  const uint32_t n = uint32_t(in.size() / kInMap);
  ASSERT_EQ(want.size(), n * kOutMap);
  std::vector<float> got = runGpu(w, in, n);
  const double err = test::maxAbsDiff(got, want);
  std::printf("golden K=8 fp32: max abs err %.3g (max |out| %.3g)\n", err, test::maxAbs(want));
  EXPECT_LE(err, 1e-4);
}

// Stated fp16 bound against PyTorch fp32: 2e-2 absolute on outputs of magnitude ~1.
TEST(UNet, MatchesPyTorchGoldenFp16) {
  nn::UNetWeights w = nn::UNetWeights::load(test::dataPath("unet_k8_fp16.osrw"));
  ASSERT_TRUE(w.halfStorage);
  std::vector<float> in = readFloats(test::dataPath("unet_k8_golden/input.f32"));
  std::vector<float> want = readFloats(test::dataPath("unet_k8_golden/output.f32"));
  const uint32_t n = uint32_t(in.size() / kInMap);
  nn::UNetOptions opt;
  opt.half = true;
  std::vector<float> got = runGpu(w, in, n, opt);
  const double err = test::maxAbsDiff(got, want);
  std::printf("golden K=8 fp16: max abs err %.3g (max |out| %.3g)\n", err, test::maxAbs(want));
  EXPECT_LE(err, 2e-2);
}

TEST(UNet, FreshPyTorchModelEndToEnd) {
  const char* py = "/usr/bin/python3";
  if (std::system((std::string(py) + " -c 'import torch' >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no torch";
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("osr_unet_e2e_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string tools = test::sourcePath("tools");
  const std::string ckpt = (dir / "model.pt").string(), packed = (dir / "model.osrw").string();
  const std::string make = std::string(py) + " -c \"import sys; sys.path.insert(0, '" + tools +
                           "'); import unet, torch; m = unet.UNet(16); unet.randomize(m, 4242); "
                           "torch.save(m.state_dict(), '" + ckpt + "')\"";
  ASSERT_EQ(std::system(make.c_str()), 0);
  const std::string pack = std::string(py) + " " + tools + "/weights_pack.py " + ckpt + " " + packed +
                           " --golden " + (dir / "golden").string() + " --golden-maps 5";
  ASSERT_EQ(std::system(pack.c_str()), 0);
  nn::UNetWeights w = nn::UNetWeights::load(packed);
  EXPECT_EQ(w.k, 16u);
  std::vector<float> in = readFloats((dir / "golden/input.f32").string());
  std::vector<float> want = readFloats((dir / "golden/output.f32").string());
  std::vector<float> got = runGpu(w, in, 5);
  const double err = test::maxAbsDiff(got, want);
  std::printf("fresh PyTorch K=16: max abs err %.3g (max |out| %.3g)\n", err, test::maxAbs(want));
  EXPECT_LE(err, 1e-4);
  fs::remove_all(dir);
}
