#include "app/frames.h"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "common/error.h"
#include "image/image_io.h"

namespace osr::app {

namespace {

constexpr int kMaxFrame = 999999;

// A frame number of at most six digits; nullopt for anything else (signs, spaces, letters).
std::optional<int> frameNumber(const std::string& text) {
  if (text.empty() || text.size() > 6) return std::nullopt;
  for (char c : text)
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
  return std::stoi(text);
}

// The last run of '#' in the file name part of `pattern`: [begin, end), or begin == npos.
std::pair<size_t, size_t> frameField(const std::string& pattern) {
  const size_t slash = pattern.find_last_of('/');
  const size_t nameStart = slash == std::string::npos ? 0 : slash + 1;
  const size_t end = pattern.find_last_of('#');
  if (end == std::string::npos || end < nameStart) return {std::string::npos, 0};
  size_t begin = end;
  while (begin > nameStart && pattern[begin - 1] == '#') --begin;
  return {begin, end + 1};
}

}  // namespace

std::optional<FrameOptions> readFrameOptions(Args& args) {
  const auto range = args.value("--frames");
  const auto fps = args.number("--fps", -1e9, 1e9);
  const bool resume = args.flag("--resume");
  const auto history = args.number("--temporal-reuse", 0.0, 64.0);
  if (!range) {
    if (fps) throw InputError("--fps: an option of --frames (an animation render)");
    if (resume) throw InputError("--resume: an option of --frames (an animation render)");
    if (history) throw InputError("--temporal-reuse: an option of --frames (an animation render)");
    return std::nullopt;
  }
  FrameOptions f;
  const size_t dash = range->find('-');
  const auto first = frameNumber(range->substr(0, dash));
  const auto last = dash == std::string::npos ? first : frameNumber(range->substr(dash + 1));
  if (!first || !last)
    throw InputError("--frames: '" + *range + "' is not a frame range A-B (or one frame A) of " +
                     "whole numbers 0 to " + std::to_string(kMaxFrame));
  if (*last < *first)
    throw InputError("--frames: '" + *range + "' ends before it starts (A-B needs A <= B)");
  f.first = *first;
  f.last = *last;
  if (fps) {
    if (!(*fps > 0.0)) throw InputError("--fps: must be above 0 frames per second");
    f.fps = *fps;
  }
  f.resume = resume;
  if (history) f.temporalHistory = float(*history);
  return f;
}

std::string framePath(const std::string& pattern, int frame) {
  const auto [begin, end] = frameField(pattern);
  if (begin == std::string::npos) return pattern;
  char digits[32];
  std::snprintf(digits, sizeof digits, "%0*d", int(end - begin), frame);
  return pattern.substr(0, begin) + digits + pattern.substr(end);
}

void checkFrameField(const std::string& option, const std::string& pattern) {
  if (frameField(pattern).first == std::string::npos)
    throw InputError(option + " " + pattern +
                     ": --frames needs a frame field in the file name, a run of '#' that the " +
                     "frame number replaces (shot_####.exr)");
}

bool frameComplete(const std::vector<std::string>& outputs) {
  for (const std::string& path : outputs)
    if (!image::isCompleteImage(path)) return false;
  return !outputs.empty();
}

void renderShot(const FrameOptions& frames, HostScene& host, bool quiet,
                const std::optional<std::string>& exrPattern,
                const std::optional<std::string>& pngPattern,
                const std::function<void(const scene::PoseChange&)>& prepare,
                const RenderFrame& render) {
  const auto start = std::chrono::steady_clock::now();
  int skipped = 0;
  for (int f = frames.first; f <= frames.last; ++f) {
    const int index = f - frames.first + 1;
    std::optional<std::string> exr, png;
    if (exrPattern) exr = framePath(*exrPattern, f);
    if (pngPattern) png = framePath(*pngPattern, f);
    std::vector<std::string> files;
    for (const auto& path : {exr, png})
      if (path) files.push_back(*path);
    if (frames.resume && frameComplete(files)) {
      ++skipped;
      if (!quiet)
        std::fprintf(stderr, "osr-vk: frame %d/%d (frame %d): %s complete, skipped (--resume)\n",
                     index, frames.count(), f, files.size() == 1 ? files[0].c_str() : "its files");
      continue;
    }
    const double t = frames.timeS(f);
    const scene::PoseChange change = scene::poseScene(host.scene, t);
    // The chosen file camera as posed; a made-up camera (the file has none) stays where it is.
    for (const scene::Camera& c : host.scene.cameras)
      if (host.camera.fileIndex >= 0 && c.fileIndex == host.camera.fileIndex)
        host.camera.worldFromCamera = c.worldFromCamera;
    prepare(change);
    if (!quiet) std::fprintf(stderr, "osr-vk: frame %d/%d (frame %d at %.3f s)\n", index, frames.count(), f, t);
    render(f, host.camera, exr, png);
  }
  if (!quiet) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "osr-vk: %d frames in %.2f s", frames.count(), s);
    if (skipped) std::fprintf(stderr, ", %d skipped (--resume)", skipped);
    std::fputc('\n', stderr);
  }
}

}  // namespace osr::app
