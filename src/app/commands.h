// The osr-vk subcommands. Each takes the arguments after its name and returns the exit code;
// errors are thrown as InputError (exit 2) or other exceptions (exit 1) and printed by main.
#pragma once
#include <string>
#include <vector>

namespace osr::app {

// The version osr-vk --version prints and maps writes into index.json.
inline constexpr char kVersion[] = "0.1.0";

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
// osr-vk compare TEST REF
inline constexpr char kCompareUsage[] =
    "usage: osr-vk compare TEST.exr REF.exr\n"
    "  compares the image under test with the reference (second): prints one JSON line with\n"
    "  relmse (mean (TEST - REF)^2 / (REF^2 + 0.01)), psnr and ssim (tone-mapped), and\n"
    "  lum_ratio (mean luminance of TEST over REF's); a TEST k times REF's size in both\n"
    "  directions (a 512 x 512 render against a 256 x 256 reference) is box-filtered down\n"
    "  first, and the line says by how much (test_downsampled_by)\n";
int runCompare(const std::vector<std::string>& args);
// osr-vk maps scene.gltf --out DIR (--grid R | --pixels x,y;...)
inline constexpr char kMapsUsage[] =
    "usage: osr-vk maps scene.gltf|scene.glb --out DIR (--grid R | --pixels x,y;x,y;...)\n"
    "                   [--reference-spp N] [--views V] [--width W] [--height H]\n"
    "                   [--camera N|name] [--env file] [--seed S] [--device N|name]\n"
    "                   [--validation] [--quiet]\n"
    "  traces hemisphere maps for training (docs/maps_format.md): for each view v < V (default\n"
    "  1, the camera jittered per view) at the --pixels given or one jittered pixel per R x R\n"
    "  cell, skipping pixels that see no surface, the one-shot input (1 path per texel) and,\n"
    "  with --reference-spp N > 0, an independent reference of the same points (N per texel).\n"
    "  Writes DIR/input.npy [N,7,32,32] float32 (radiance RGB, hit normal XYZ, distance),\n"
    "  DIR/target.npy [N,3,32,32] float32 (reference radiance; with --reference-spp),\n"
    "  DIR/points.npy [N,3] int32 (view, x, y) and DIR/index.json (the settings)\n";
int runMaps(const std::vector<std::string>& args);

}  // namespace osr::app
