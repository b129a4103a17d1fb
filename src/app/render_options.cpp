#include "app/render_options.h"

#include <filesystem>

#include "app/args.h"
#include "app/device_options.h"
#include "common/error.h"

namespace osr::app {

RenderOptions parseRenderOptions(const std::vector<std::string>& args) {
  Args a(args, "render");
  RenderOptions o;
  o.exrPath = a.value("--offline");
  o.pngPath = a.value("--png");
  o.exposure = a.number("--exposure", -64, 64);
  o.integrator = readIntegratorOptions(a);
  o.timeLimit = a.number("--time", 0.001, 1e7);
  o.seed = a.integer("--seed", 0, 0xffffffffll);
  o.scene = readSceneOptions(a);
  o.exrFloat = a.flag("--exr-float");
  o.quiet = a.flag("--quiet");
  o.dumpMaps = a.value("--dump-maps");
  o.viewerScript = a.value("--viewer-script");
  o.saveDir = a.value("--save-dir");
  o.crop = a.integerList("--crop", 0, 16384);
  o.frames = readFrameOptions(a);
  // A crop is a tile of a larger image (tools/osr_farm.py): filtered per tile, its edges would
  // not match its neighbours', so only a denoiser asked for runs.
  if (o.crop && !o.integrator.everyMode.denoise.chosen) o.integrator.everyMode.denoise = {};
  o.integrator.everyMode.denoise.check();  // a bad model: one line and exit 2 before any work
  o.device = readDeviceOptions(a);
  auto files = a.positional();
  a.finish();
  if (files.size() != 1) throw InputError("render: expected exactly one scene file");
  o.scenePath = files[0];
  return o;
}

IntegratorSettings checkRenderOptions(const RenderOptions& o) {
  IntegratorSettings settings = buildIntegratorSettings(o.integrator);
  // The map cache pays where views follow each other: camera moves, a shot's frames.
  if (!o.integrator.osr.mapCache && (o.live() || o.frames))
    settings.osr.mapCacheMaps = oneshot::kDefaultMapCacheMaps;
  // A shot's frames refine the maps they share until they are clean (osr_settings.h).
  if (o.frames) settings.osr.mapCacheMaturePasses = oneshot::kShotMatureMapPasses;
  // The viewer shows an image soon after a move: light first passes (docs/viewer.md).
  if (o.live()) settings.osr.quickPasses = oneshot::kViewerQuickPasses;
  if (o.dumpMaps && o.integrator.mode != "osr")
    throw InputError("--dump-maps: an option of --mode osr");
  if (o.exposure && !o.live() && !o.pngPath)
    throw InputError(
        "--exposure: sets the exposure of the --png preview (the EXR holds radiance); "
        "give --png too");
  if (o.exrFloat && !o.exrPath) throw InputError("--exr-float: an option of the --offline EXR");
  if (o.live() && o.dumpMaps)
    throw InputError("--dump-maps: an option of --offline/--png renders (the viewer saves with S)");
  if (!o.live() && (o.viewerScript || o.saveDir))
    throw InputError(
        "render: --viewer-script and --save-dir are options of the viewer "
        "(without --offline/--png)");
  // Checked now, not at the first save: every S in the window would fail with it.
  std::error_code ec;  // a name the system refuses (too long, a loop) is not a folder either
  if (o.saveDir && !std::filesystem::is_directory(*o.saveDir, ec))
    throw InputError("--save-dir: " + *o.saveDir + " is not a folder" +
                     (ec && ec != std::errc::no_such_file_or_directory ? " (" + ec.message() + ")" : ""));
  if (o.live() && o.crop) throw InputError("--crop: an option of --offline/--png renders");
  if (o.crop && (o.crop->size() != 4 || (*o.crop)[2] < 1 || (*o.crop)[3] < 1))
    throw InputError("--crop: expected X,Y,W,H (the window's corner and size, W and H >= 1)");
  if (o.frames) {
    if (o.live()) throw InputError("--frames: an option of --offline/--png renders (give --offline)");
    if (o.dumpMaps) throw InputError("--dump-maps: not with --frames (one frame's maps)");
    if (o.exrPath) checkFrameField("--offline", *o.exrPath);
    if (o.pngPath) checkFrameField("--png", *o.pngPath);
  }
  settings.keepAllMaps = bool(o.dumpMaps);
  return settings;
}

}  // namespace osr::app
