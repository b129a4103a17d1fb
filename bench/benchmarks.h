// The benchmarks of osr-bench; each prints JSON lines (see bench/json.h) and returns an exit
// code. Each usage is printed by `osr-bench NAME --help`.
#pragma once
#include <string>
#include <vector>

namespace osr::bench {
// Each benchmark: a one-line summary (`osr-bench` with no name lists them) and its usage with
// every option, its range and default (`osr-bench NAME --help`).
inline constexpr char kFillSummary[] = "memory bandwidth of the simplest pass (sanity figure)";
inline constexpr char kFillUsage[] = "osr-bench fill   (no options)";
int runFill(const std::vector<std::string>& args);  // memory bandwidth of util_fill
inline constexpr char kPathtraceSummary[] =
    "path tracer samples/s and relMSE (equal samples, equal time) against Cycles";
inline constexpr char kPathtraceUsage[] =
    "osr-bench pathtrace [--scene cornell|room] [--size N] [--spp N]\n"
    "  --scene NAME   one reference scene (default: cornell and room)\n"
    "  --size N       image width and height, 8 to 4096 (default 256; relMSE at 256 only)\n"
    "  --spp N        samples per pixel timed, 1 to 1048576 (default 64)\n"
    "  With blender on PATH (apt-get install blender) Cycles renders the same scene in the\n"
    "  same run, and ours renders again for Cycles' time (equal-time relMSE).";
int runPathtrace(const std::vector<std::string>& args);  // path tracer spp/s, Mpaths/s
inline constexpr char kBvhSummary[] = "GPU BVH build time and quality against CPU SAH and Embree";
inline constexpr char kBvhUsage[] =
    "osr-bench bvh [--scene NAME | --triangles N] [--repeat N] [--treelet-rounds N]\n"
    "              [--treelet-leaves N] [--treelet-min-triangles N] [--hierarchy auto|lbvh|ploc]\n"
    "              [--ploc-local-rounds N] [--ploc-tail-clusters N] [--no-cpu-reference]\n"
    "  --scene NAME               generated_1m, cornell or room (default: all)\n"
    "  --triangles N              instead, a displaced sphere of at least N triangles, 1 to the\n"
    "                             device's limit (scale: memory per triangle)\n"
    "  --no-cpu-reference         skip the CPU binned-SAH build (slow past millions of triangles)\n"
    "  --repeat N                 builds timed per scene, 1 to 100 (default 3)\n"
    "  --treelet-rounds N         treelet optimization rounds, 0 to 8 (default: 2 under 16,384\n"
    "                             triangles, else 1, as the renderer builds)\n"
    "  --treelet-leaves N         leaves per treelet, 3 to the build's maximum\n"
    "  --treelet-min-triangles N  smallest subtree a treelet round visits, 3 to 1048576\n"
    "  --hierarchy H              lbvh (then treelets) or ploc (then a treelet round over the\n"
    "                             upper tree); auto: ploc from 500,000 triangles where the\n"
    "                             build's arrays fit one storage binding, as the renderer builds\n"
    "  --ploc-local-rounds N      PLOC's rounds of merges within chunks of 8 clusters before its\n"
    "                             global iterations, 0 to 4 (default 0)\n"
    "  --ploc-tail-clusters N     PLOC's global iterations stop at N clusters or fewer and one\n"
    "                             workgroup finishes the tree, 0 (none) to 16384 (default 1024)";
int runBvh(const std::vector<std::string>& args);   // GPU BVH build vs CPU SAH and Embree
inline constexpr char kTraceSummary[] = "rays/s of BVH traversal against Embree";
inline constexpr char kTraceUsage[] =
    "osr-bench trace [--scene NAME | --triangles N] [--side N] [--repeat N]\n"
    "                [--bvh-access auto|storage|texel] [--rays-per-lane N,...]\n"
    "                [--hierarchy auto|lbvh|ploc] [--ploc-local-rounds N] [--ploc-tail-clusters N]\n"
    "  --scene NAME       generated_1m, cornell or room (default: all)\n"
    "  --triangles N      instead, a displaced sphere of at least N triangles\n"
    "  --side N           rays = N x N, 16 to 2048 (default 1024)\n"
    "  --repeat N         timed repeats, 1 to 100 (default 3)\n"
    "  --bvh-access MODE  how traversal reads the BVH: storage buffers, texel fetches or the\n"
    "                     device's choice (default auto)\n"
    "  --rays-per-lane N,...  rays each invocation takes in turn from its subgroup's pool, 1 to\n"
    "                     64, one line each (default 1,16); 1 traces one ray per invocation, as\n"
    "                     the renderers' kernels do\n"
    "  --hierarchy H      how the BVH is built (osr-bench bvh --help; default auto)\n"
    "  --ploc-local-rounds N  PLOC's local merge rounds (osr-bench bvh --help)\n"
    "  --ploc-tail-clusters N  where PLOC's one-workgroup tail starts (osr-bench bvh --help)";
int runTrace(const std::vector<std::string>& args); // rays/s of bvh_trace_rays vs Embree
inline constexpr char kUnetSummary[] = "U-Net maps/s against PyTorch on the same cores";
inline constexpr char kUnetUsage[] =
    "osr-bench unet [--k 16,64] [--batch 64,256,1024,4096] [--precision fp32,fp16]\n"
    "               [--no-pytorch] [--min-seconds S] [--tile HxW] [--chunk N] [--share N]\n"
    "               [--profile]\n"
    "  --k LIST           network widths K, each 1 to 1024 (default 16,64)\n"
    "  --batch LIST       maps per batch, each 1 to 1048576 (default 64,256,1024,4096)\n"
    "  --precision LIST   fp32 and/or fp16 (default both)\n"
    "  --no-pytorch       skip the PyTorch peer\n"
    "  --min-seconds S    time each point for at least S seconds, 0 to 3600 (default 2)\n"
    "  --tile HxW         convolution output tile, each 1 to 32 (default: the device's)\n"
    "  --chunk N          largest maps per dispatch chunk, 1 to 1048576\n"
    "  --share N          lanes sharing loads, 1 (none) to 65 (default: the device's)\n"
    "  --profile          per-pass GPU times of one batch on stderr";
int runUnet(const std::vector<std::string>& args);  // U-Net maps/s vs PyTorch
inline constexpr char kOsrSummary[] = "One Shot Radiance against path tracing at equal time";
inline constexpr char kOsrUsage[] =
    "osr-bench osr [--scene cornell|room] [--size N] [--budgets 2,5,10,30,60]\n"
    "              [--denoiser blur|none|unet] [--weights FILE] [--modes osr,path]\n"
    "  --scene NAME       one reference scene (default: cornell and room)\n"
    "  --size N           image width and height, 8 to 4096 (default 256)\n"
    "  --budgets LIST     time budgets in seconds, each 1 to 3600 (default 2,5,10,30,60)\n"
    "  --denoiser NAME    OSR map denoiser (default blur; unet with --weights)\n"
    "  --weights FILE     packed U-Net weights\n"
    "  --modes LIST       osr,path, osr or path (default osr,path)";
int runOsr(const std::vector<std::string>& args);   // OSR vs path tracing at equal time
inline constexpr char kDenoiseSummary[] = "image denoisers at equal time (denoise time in the budget)";
inline constexpr char kDenoiseUsage[] =
    "osr-bench denoise [--scene cornell|room|FILE.gltf] [--reference FILE.exr] [--size N]\n"
    "                  [--budgets 5,10,30] [--network default|none|FILE] [--env FILE] [--camera NAME]\n"
    "                  [--rows LIST]\n"
    "  --scene NAME       a reference scene (default cornell) or a glTF file (needs --reference)\n"
    "  --env FILE         an environment map (.hdr, .exr) lighting the scene, as osr-vk --env\n"
    "  --camera NAME      the glTF camera (name or index) the reference was rendered from\n"
    "  --reference FILE   the reference EXR (default: the scene's 4096-spp Cycles render)\n"
    "  --size N           image width and height, 8 to 4096 (default 256)\n"
    "  --budgets LIST     time budgets in seconds, each 1 to 3600 (default 5,10,30)\n"
    "  --network NAME     the image denoiser: default (the shipped model), none (the\n"
    "                     network rows are left out) or a packed file\n"
    "  --rows LIST        the rows to run, comma-separated, of path, path+atrous, osr,\n"
    "                     osr+atrous, path+network, osr+network (default: all)";
int runDenoise(const std::vector<std::string>& args);  // denoisers at equal time
inline constexpr char kOsrErrorSummary[] =
    "where OSR's error is: direct, maps' and residual noise and bias, over seeds";
inline constexpr char kOsrErrorUsage[] =
    "osr-bench osr-error [--scene cornell|room|FILE.gltf] [--reference FILE.exr] [--env FILE]\n"
    "                    [--camera NAME] [--size N] [--budgets 5,10,30,60 | --passes LIST]\n"
    "                    [--seeds N] [--map-spp K] [--network default|none|FILE]\n"
    "  --scene, --reference, --env, --camera  as osr-bench denoise; a reference with direct\n"
    "                     and indirect layers (tools/merge_references.py of raw path-traced\n"
    "                     renders) splits the bias by layer too\n"
    "  --size N           image width and height, 8 to 4096 (default 256)\n"
    "  --budgets LIST     seconds, each 1 to 3600: OSR's passes in each (seed 1) are the passes\n"
    "                     every seed then makes (default 5,10,30,60)\n"
    "  --passes LIST      instead, the passes, each 1 to 65536 (figures that do not move with\n"
    "                     the load on shared cores; budget_s 0 in the lines)\n"
    "  --seeds N          renders per budget whose spread is the noise, 2 to 64 (default 4)\n"
    "  --map-spp K        paths per map texel of the renders that find the maps' noise, 2 to\n"
    "                     1024 (default 4)\n"
    "  --network NAME     the image denoiser whose output is split too: default, none or a\n"
    "                     packed file (default: default)";
int runOsrError(const std::vector<std::string>& args);  // OSR's error split by source
inline constexpr char kSoakSummary[] =
    "the viewer scripted for 20 minutes under Xvfb: memory growth, validation, saved files";
inline constexpr char kSoakUsage[] =
    "osr-bench soak [--minutes M] [--scene cornell|room|FILE.gltf]\n"
    "  --minutes M   length of the run, 1 to 600 (default 20): one-minute cycles of camera\n"
    "                moves, mode and layer changes, resizes, saves (S) and a screenshot\n"
    "  --scene NAME  a reference scene or a glTF file (default room)\n"
    "  Runs osr-vk's viewer under xvfb-run with the validation layer on; passes when resident\n"
    "  memory grows < 5 % from the end of the first cycle to the end of the last, no\n"
    "  validation message appears, every saved file is a whole image and osr-vk exits 0.";
int runSoak(const std::vector<std::string>& args);  // the viewer for many minutes
inline constexpr char kAnimationSummary[] =
    "a camera path as frames: seconds per frame with and without the map cache, relMSE, flicker";
inline constexpr char kAnimationUsage[] =
    "osr-bench animation [--scene FILE.gltf] [--env FILE] [--frames A-B] [--fps N] [--size N]\n"
    "                    [--passes N] [--cache-passes N] [--map-cache N] [--mature-passes N]\n"
    "                    [--reference-frames LIST] [--reference-spp N] [--cache DIR] [--png DIR]\n"
    "                    [--temporal-reuse F] [--path-only SPP]\n"
    "  --scene FILE       a glTF file with an animated camera (default: generated interior 9002\n"
    "                     with a 48-frame walk, made in the cache folder by tools/make_interiors.py\n"
    "                     and tools/add_camera_path.py)\n"
    "  --env FILE         environment map (default: the generated interior's sky.hdr)\n"
    "  --frames A-B       frames rendered (default 0-47), at least two; --fps as osr-vk (24)\n"
    "  --size N           image width and height, 8 to 4096 (default 256)\n"
    "  --passes N         OSR passes per frame without the map cache, 1 to 4096 (default 4)\n"
    "  --cache-passes N   OSR passes per frame with the map cache, 1 to 4096 (default passes / 2)\n"
    "  --map-cache N      maps the cache holds, 4 to 1048576 (default 4096, as osr-vk --frames)\n"
    "  --mature-passes N  map passes a cached map averages before it is reused untraced, 0 to\n"
    "                     4096 (default 8, as osr-vk --frames; 0: as the viewer)\n"
    "  --reference-frames LIST  frames with a path-traced reference, inside --frames, two of them\n"
    "                     consecutive (flicker) (default 24,25,26,27)\n"
    "  --reference-spp N  samples per pixel of the references, 1 to 1048576 (default 256)\n"
    "  --cache DIR        where the default scene and the references are kept (default\n"
    "                     $TMPDIR/osr-bench-animation); a rerun reuses references of the same\n"
    "                     scene files, size, fps and spp\n"
    "  --png DIR          also write each sequence's reference frames and the references as PNG\n"
    "  --temporal-reuse F path+reuse+network's history cap, 0.5 to 64 (default 3, as osr-vk --frames)\n"
    "  --path-only SPP    only the path-traced sequences, path given SPP samples a frame\n"
    "  Sequences: osr (no cache), osr+cache, path (at osr+cache's CPU seconds per frame), path+atrous\n"
    "  and path+network (the same CPU seconds, the denoiser's included), path+reuse+network (half\n"
    "  path+network's samples, with temporal reuse: osr-vk --frames' default), osr+network,\n"
    "  osr+cache+network, and the references' own flicker (converged).";
int runAnimation(const std::vector<std::string>& args);  // a camera path: cache, relMSE, flicker
}  // namespace osr::bench
