// `osr-vk --frames A-B [--fps N] [--resume]`: which frames a shot renders, at what scene time,
// under which file names, and which of them a resumed shot may skip. The render loop itself is
// in cmd_render.cpp; this is what it needs that is not rendering.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/args.h"
#include "app/scene_setup.h"
#include "render/temporal_reuse.h"
#include "scene/animation.h"

namespace osr::app {

inline constexpr double kDefaultFps = 24.0;

struct FrameOptions {
  int first = 0, last = 0;  // inclusive
  double fps = kDefaultFps;
  bool resume = false;
  // --temporal-reuse: the most each frame counts the frames before it for, in its own
  // samples' worth (render/temporal_reuse.h); 0 renders every frame on its own.
  float temporalHistory = render::kDefaultTemporalHistory;
  int count() const { return last - first + 1; }
  double timeS(int frame) const { return frame / fps; }  // frame f is at f / fps seconds
};

// Consumes --frames, --fps, --resume and --temporal-reuse; nullopt without --frames.
// InputError on a range that is not "A-B" (or one frame "A") with 0 <= A <= B <= 999999, on
// --fps <= 0, --temporal-reuse outside 0-64, and on any of the others without --frames.
std::optional<FrameOptions> readFrameOptions(Args& args);

// `pattern` with its last run of '#' replaced by `frame`, zero padded to the run's length
// (more digits when the number needs them): shot_####.exr, 12 -> shot_0012.exr.
std::string framePath(const std::string& pattern, int frame);
// InputError unless `pattern` (the value of `option`) has a run of '#' in its file name.
void checkFrameField(const std::string& option, const std::string& pattern);

// Whether every one of a frame's outputs is a complete image (image::isCompleteImage), so
// that --resume may skip it.
bool frameComplete(const std::vector<std::string>& outputs);

// Renders a shot: for each frame, unless --resume finds its files complete (a line says it is
// skipped), poses host.scene at the frame's time, calls `prepare` with what moved (to upload
// the scene again where it must), then `render` with the frame's number through host.camera
// as posed into the frame's files. Unless `quiet`, "osr-vk: frame F/N (frame K at T s)"
// precedes each frame's progress lines and one line ends the shot (README "Progress").
using RenderFrame = std::function<void(int frame, const scene::Camera& camera,
                                       const std::optional<std::string>& exrPath,
                                       const std::optional<std::string>& pngPath)>;
void renderShot(const FrameOptions& frames, HostScene& host, bool quiet,
                const std::optional<std::string>& exrPattern,
                const std::optional<std::string>& pngPattern,
                const std::function<void(const scene::PoseChange&)>& prepare,
                const RenderFrame& render);

}  // namespace osr::app
