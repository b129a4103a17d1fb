// osr-vk entry point: picks the subcommand and turns exceptions into one stderr line and the
// exit code of DESIGN.md (2 bad input, 1 internal or device error).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "app/commands.h"
#include "common/error.h"

namespace {

constexpr const char* kUsage =
    "usage: osr-vk [options] scene.gltf|scene.glb\n"
    "       osr-vk --list-devices\n"
    "       osr-vk unet --weights FILE --in maps.f32 --out pred.f32 [--precision fp32|fp16]\n"
    "       osr-vk compare a.exr b.exr   relmse, psnr, ssim, lum_ratio as one JSON line\n"
    "\n"
    "render options:\n"
    "  --offline out.exr     render without a window and write a multi-layer OpenEXR\n"
    "  --png out.png         also write a tone-mapped PNG preview\n"
    "  --mode path|preview   integrator (default path; preview: albedo x headlight cosine)\n"
    "  --spp N               samples per pixel (default 64; preview 4)\n"
    "  --time SECONDS        stop after this long (with --spp: whichever ends first)\n"
    "  --seed N              random seed (same seed, same image)\n"
    "  --exposure EV         PNG exposure (default: automatic)\n"
    "  --exr-float           32-bit float EXR channels (default half)\n"
    "  --width N --height N  image size (default 512 wide, camera aspect)\n"
    "  --camera N|name       glTF camera to use (default: first, or one framing the scene)\n"
    "  --env file.exr|.hdr   equirectangular environment light\n"
    "  --device N|name       Vulkan device (see --list-devices)\n"
    "  --validation          enable the Khronos validation layer\n"
    "  --quiet               no progress output\n";

struct Command {
  const char* name;
  int (*run)(const std::vector<std::string>&);
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty()) {
      std::fputs(kUsage, stderr);
      return osr::kExitBadInput;
    }
    if (args[0] == "--help" || args[0] == "-h") {
      std::fputs(kUsage, stdout);
      return osr::kExitOk;
    }
    static const Command kCommands[] = {
        {"--list-devices", osr::app::runListDevices},
        {"unet", osr::app::runUnet},
        {"compare", osr::app::runCompare},
    };
    for (const Command& c : kCommands)
      if (args[0] == c.name) return c.run({args.begin() + 1, args.end()});
    return osr::app::runRender(args);
  } catch (const osr::InputError& e) {
    std::fprintf(stderr, "osr-vk: %s\n", e.what());
    return osr::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "osr-vk: error: %s\n", e.what());
    return osr::kExitInternal;
  }
}
