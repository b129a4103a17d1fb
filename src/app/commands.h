// The osr-vk subcommands. Each takes the arguments after its name and returns the exit code;
// errors are thrown as InputError (exit 2) or other exceptions (exit 1) and printed by main.
#pragma once
#include <string>
#include <vector>

namespace osr::app {

// osr-vk [options] scene.gltf: render (viewer, or --offline out.exr).
int runRender(const std::vector<std::string>& args);
// osr-vk --list-devices
inline constexpr char kListDevicesUsage[] =
    "usage: osr-vk --list-devices\n"
    "  prints index: name (type, Vulkan version) of each Vulkan device, for --device\n";
int runListDevices(const std::vector<std::string>& args);
// osr-vk unet --weights FILE --in maps.f32 --out pred.f32
inline constexpr char kUnetUsage[] =
    "usage: osr-vk unet --weights FILE --in maps.f32 --out pred.f32 [--precision fp32|fp16]\n"
    "                   [--device N|name] [--validation] [--quiet]\n"
    "  runs the packed U-Net on raw little-endian fp32 N x 7 x 32 x 32 maps and writes\n"
    "  N x 3 x 32 x 32 predictions (precision: default the weights file's storage)\n";
int runUnet(const std::vector<std::string>& args);
// osr-vk compare a.exr b.exr
inline constexpr char kCompareUsage[] =
    "usage: osr-vk compare a.exr b.exr\n"
    "  prints relmse, psnr, ssim and lum_ratio (a over b) as one JSON line\n";
int runCompare(const std::vector<std::string>& args);

}  // namespace osr::app
