// osr-vk unet --weights FILE --in maps.f32 --out pred.f32: runs the packed network alone on
// raw little-endian fp32 N x 7 x 32 x 32 maps and writes N x 3 x 32 x 32 predictions, the
// way to check the engine from outside (e.g. against PyTorch on the same file).
#include <cstdio>
#include <fstream>

#include "app/args.h"
#include "app/commands.h"
#include "app/device_options.h"
#include "app/maps_file.h"
#include "app/output_paths.h"
#include "common/error.h"
#include "nn_kernels/unet.h"
#include "nn_kernels/weights_format.h"
#include "vk/buffer.h"
#include "vk/context.h"

namespace osr::app {

int runUnet(const std::vector<std::string>& args) {
  Args a(args, "unet");
  auto weightsPath = a.value("--weights");
  auto inPath = a.value("--in");
  auto outPath = a.value("--out");
  auto precision = a.value("--precision");
  vk::ContextOptions options = readDeviceOptions(a);
  const bool quiet = a.flag("--quiet");
  a.finish();
  if (!weightsPath || !inPath || !outPath)
    throw InputError("unet: --weights, --in and --out are required (usage: osr-vk unet --help)");
  // Not checkOutputs: --out may be /dev/null or a pipe, which a rename must not replace.
  for (const auto& [role, path] :
       {std::pair{"the --in maps", *inPath}, {"the --weights file", *weightsPath}})
    if (sameFile(*outPath, path))
      throw InputError("--out " + *outPath + ": is " + role +
                       ", which this command reads; refusing to overwrite it");
  if (precision && *precision != "fp32" && *precision != "fp16")
    throw InputError("unet: --precision must be fp32 or fp16, not '" + *precision + "'");

  nn::UNetWeights weights = nn::UNetWeights::load(*weightsPath);
  const MapsFile input = readMapsFile(*inPath);
  const std::vector<char>& bytes = input.bytes;
  const uint32_t maps = input.maps;
  const size_t outBytes = size_t(maps) * nn::kOutChannels * nn::kMapSize * nn::kMapSize * 4;

  vk::Context ctx(options);
  nn::UNetOptions netOptions;
  netOptions.half = precision ? *precision == "fp16" : weights.halfStorage;
  nn::UNet net(ctx, weights, netOptions);
  vk::Buffer inBuf(ctx, bytes.size(), vk::MemoryUse::DeviceLocal, "unet input maps");
  inBuf.upload(bytes.data(), bytes.size());
  vk::Buffer outBuf(ctx, outBytes, vk::MemoryUse::DeviceLocal, "unet predictions");
  ctx.submitAndWait([&](VkCommandBuffer cmd) { net.record(cmd, inBuf, 0, outBuf, 0, maps); });
  std::vector<char> result(outBytes);
  outBuf.download(result.data(), outBytes);
  std::ofstream out(*outPath, std::ios::binary);
  if (!out.write(result.data(), std::streamsize(outBytes)))
    throw InputError(*outPath + ": cannot write predictions");
  if (!quiet)
    std::fprintf(stderr, "unet: K=%u %s, %u maps -> %s\n", weights.k, netOptions.half ? "fp16" : "fp32",
                 maps, outPath->c_str());
  return kExitOk;
}

}  // namespace osr::app
