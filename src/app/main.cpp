// osr-vk entry point: picks the subcommand and turns exceptions into one stderr line and the
// exit code of DESIGN.md (2 bad input, 1 internal or device error). `--help` or `-h` anywhere
// in a subcommand's arguments prints that subcommand's usage on stdout and exits 0.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "app/args.h"
#include "app/commands.h"
#include "app/denoise_options.h"
#include "app/integrators.h"
#include "common/error.h"
#include "nn_kernels/weights_format.h"
#include "osr_git_version.h"
#include "viewer/viewer.h"

namespace {

constexpr const char* kUsage =
    "usage: osr-vk [options] scene.gltf|scene.glb\n"
    "       osr-vk --list-devices\n"
    "       osr-vk unet --weights FILE --in maps.f32 --out pred.f32 [--precision fp32|fp16]\n"
    "       osr-vk compare TEST.exr REF.exr   relmse, psnr, ssim, lum_ratio as one JSON line\n"
    "       osr-vk maps scene.gltf --out DIR (--grid R | --pixels x,y;...) [--reference-spp N]\n"
    "                                    hemisphere maps for training (osr-vk maps --help)\n"
    "\n"
    "render options:\n"
    "  --offline out.exr     render without a window and write a multi-layer OpenEXR\n"
    "                        (without --offline and --png: the live viewer, below)\n"
    "  --png out.png         also write a tone-mapped PNG preview\n"
    "                        (an output may not be an input or the other output: exit 2)\n"
    "  --mode path|osr|preview  integrator (default path): path tracing (denoised by the learned\n"
    "                        denoiser, the lowest error at equal time measured: docs/denoise.md),\n"
    "                        osr (One Shot Radiance: noise-free early, converges to path) or\n"
    "                        preview (albedo x headlight cosine, instant)\n";
// Then osr::app::unitOptionsHelp(): --spp and --passes with the registry's defaults.
constexpr const char* kUsageOptions =
    "  --time SECONDS        stop after this long from the start, even inside a pass, and\n"
    "                        write what was rendered (with --spp/--passes: whichever ends\n"
    "                        first); Ctrl-C does the same, twice exits at once\n"
    "  --seed N              random seed (same seed, same image)\n"
    "  --exposure EV         PNG exposure (default: automatic, metered on what was hit or lit)\n"
    "  --exr-float           32-bit float EXR channels (default half)\n"
    "  --width N --height N  image size (default 512 wide, camera aspect; up to 16384)\n"
    "  --crop X,Y,W,H        render only that window of the image (the same pixels as the\n"
    "                        whole render's: path mode bit for bit; tools/osr_farm.py tiles)\n"
    "  --frames A-B          render frames A to B of the glTF's animations (frame f at\n"
    "                        f / fps s) into --offline/--png names whose run of '#' takes\n"
    "                        the frame number (shot_####.exr); --spp/--passes/--time per frame\n"
    "  --fps N               frames per second of --frames (default 24)\n"
    "  --resume              --frames: skip frames whose files are complete images\n"
    "  --temporal-reuse F    --frames: blend each frame with the frames before it where they\n"
    "                        saw the same surface, their samples counting for at most F times\n"
    "                        the frame's own, in full under a still camera (default 3;\n"
    "                        0: every frame on its own)\n"
  "  --camera N|name       glTF camera by its index in the file or its name (default: the\n"
    "                        first, or a three-quarter view framing the scene)\n"
    "  --env file.exr|.hdr|none  equirectangular environment light; a scene without lights\n"
    "                        gets a neutral sky unless --env none\n"
    "  --device N|name       Vulkan device (see --list-devices)\n"
    "  --validation          enable the Khronos validation layer\n"
    "  --quiet               no progress output\n";
// After the denoiser's lines (app/denoise_options.h), which name each mode's default.
constexpr const char* kUsageTail =
    "\n"
    "osr options (docs/osr.md):\n"
    "  --denoiser unet|blur|none  map denoiser (default blur, measured better at equal time\n"
    "                        on lavapipe; unet: the built-in model, docs/training.md)\n"
    "  --weights FILE        other packed U-Net weights (implies --denoiser unet)\n"
    "  --grid-start R --grid-min R  grid spacing in pixels, first and finest (16, 16)\n"
    "  --map-share F         largest share of the work map passes may take, 0 to 1 (0.25)\n"
    "  --map-cache N         world-space map cache of N maps (12 KiB each), kept across camera\n"
    "                        moves and frames; 0: none (viewer and --frames 4096, else 0)\n"
    "  --map-cache-reach K   a shot's frame that moves an object traces again the cached\n"
    "                        maps within K x its size of it (1; a light that moves: all)\n"
    "  --direct-spp N        direct-light samples per pixel and pass (16, then 4)\n"
    "  --residual-spp N      residual paths per pixel and pass (1, then 4)\n"
    "  --residual-ramp N0    blend the residual in by k / (k + N0) after k passes (default:\n"
    "                        per pixel, where it measurably corrects the maps)\n"
    "  --residual-guide F    share of the residual's first bounces drawn from the maps on\n"
    "                        diffuse surfaces, 0 to 0.95 (0)\n"
    "  --map-spp N           paths per map texel (1)\n"
    "  --dump-maps DIR       write the last pass's maps as PNG atlases\n"
    "\n"
    "  osr-vk help [COMMAND], osr-vk COMMAND --help: usage; osr-vk --version: version\n";

struct Command {
  const char* name;
  const char* usage;  // printed on stdout by `osr-vk NAME --help` and `osr-vk help NAME`
  int (*run)(const std::vector<std::string>&);
};

const Command kCommands[] = {
    {"--list-devices", osr::app::kListDevicesUsage, osr::app::runListDevices},
    {"unet", osr::app::kUnetUsage, osr::app::runUnet},
    {"compare", osr::app::kCompareUsage, osr::app::runCompare},
    {"maps", osr::app::kMapsUsage, osr::app::runMaps},
};

const Command* findCommand(const std::string& name) {
  for (const Command& c : kCommands)
    if (name == c.name) return &c;
  return nullptr;
}

void printUsage(FILE* f) {
  std::fputs(kUsage, f);
  std::fputs(osr::app::unitOptionsHelp().c_str(), f);
  std::fputs(kUsageOptions, f);
  std::fputs(osr::app::denoiseHelp().c_str(), f);
  std::fputs(kUsageTail, f);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty()) {
      printUsage(stderr);
      return osr::kExitBadInput;
    }
    if (args[0] == "--version") {
      // The commit tells builds apart (tools/osr_farm.py checks every worker runs the same).
      std::printf("osr-vk %s (commit %s, packed weights format %u)\n", osr::app::kVersion,
                  OSR_GIT_COMMIT, osr::nn::kWeightsVersion);
      return osr::kExitOk;
    }
    if (args[0] == "help") {  // `osr-vk help [COMMAND]`
      const Command* c = args.size() > 1 ? findCommand(args[1]) : nullptr;
      if (args.size() > 1 && !c)  // a typo must not look like the answer
        throw osr::InputError("help: unknown command '" + args[1] +
                              "' (unet, compare, maps, --list-devices; osr-vk --help: render)");
      if (c) std::fputs(c->usage, stdout);
      if (!c) printUsage(stdout);
      if (!c) std::fputs(osr::viewer::kViewerHelp, stdout);
      return osr::kExitOk;
    }
    if (const Command* c = findCommand(args[0])) {
      const std::vector<std::string> rest(args.begin() + 1, args.end());
      if (osr::app::helpRequested(rest)) {
        std::fputs(c->usage, stdout);
        return osr::kExitOk;
      }
      return c->run(rest);
    }
    if (osr::app::helpRequested(args)) {  // render options, e.g. `osr-vk scene.gltf --help`
      printUsage(stdout);
      std::fputs(osr::viewer::kViewerHelp, stdout);
      return osr::kExitOk;
    }
    return osr::app::runRender(args);
  } catch (const osr::InputError& e) {
    std::fprintf(stderr, "osr-vk: %s\n", e.what());
    return osr::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "osr-vk: error: %s\n", e.what());
    return osr::kExitInternal;
  } catch (...) {
    std::fputs("osr-vk: error: unknown exception\n", stderr);
    return osr::kExitInternal;
  }
}
