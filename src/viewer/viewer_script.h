// --viewer-script FILE: a list of timed actions that drive the viewer like a person would, for
// tests and recorded demos. One command per line, '#' starts a comment; a waiting command
// holds the ones after it back:
//   at SECONDS          wait until SECONDS after the window opened
//   wait SECONDS        wait this long after the previous command
//   wait-units N        wait until the image on screen has N units (spp or passes)
//   wait-done           wait until the render's stop rule holds and its image is on screen
//   wait-image          wait until the first image since the last restart is on screen
//   key NAME            press a key: s, space, 1-6, plus, minus, f, escape (see --help)
//   orbit YAW PITCH     degrees, as a left-button drag
//   pan RIGHT UP        fractions of the view height, as a middle-button drag
//   zoom FACTOR         distance to the orbit target times FACTOR, as the scroll wheel
//   fly FORWARD RIGHT UP  scene radii, as W/A/S/D with the right button held
//   camera N            the file's camera N
//   reset               the starting camera
//   resize W H          the window's size in pixels (waits until the framebuffer has it)
//   screenshot FILE     the next frame as shown (panel included), as a PNG
//   stats               frame pacing so far as one JSON line on stdout
//   quit                close the viewer (exit 0)
#pragma once
#include <string>
#include <vector>

namespace osr::viewer {

struct ScriptCommand {
  std::string name;
  std::vector<double> numbers;
  std::string text;  // screenshot path, key name
  int line = 0;
};

// Reads and checks the whole script first: InputError "FILE:LINE: problem" for an unknown
// command, a missing or malformed argument, a `mode` not in `modes` (the viewer's
// integrators), or an unreadable file.
std::vector<ScriptCommand> readViewerScript(const std::string& path,
                                            const std::vector<std::string>& modes = {});
// The same from the script's text; `path` names it in messages.
std::vector<ScriptCommand> parseViewerScript(const std::string& text, const std::string& path,
                                             const std::vector<std::string>& modes = {});

}  // namespace osr::viewer
