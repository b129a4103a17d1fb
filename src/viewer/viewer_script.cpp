#include "viewer/viewer_script.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>

#include "common/error.h"
#include "common/input_file.h"

namespace osr::viewer {

namespace {
struct Syntax {
  const char* name;
  int numbers;  // numeric arguments
  bool text;    // one word argument after them
};
constexpr Syntax kSyntax[] = {
    {"at", 1, false},        {"wait", 1, false},       {"wait-units", 1, false},
    {"wait-done", 0, false}, {"wait-image", 0, false}, {"key", 0, true},
    {"orbit", 2, false},     {"pan", 2, false},        {"zoom", 1, false},
    {"fly", 3, false},       {"camera", 1, false},     {"reset", 0, false},
    {"resize", 2, false},    {"screenshot", 0, true},  {"stats", 0, false},
    {"quit", 0, false},      {"mode", 0, true},
};
// Every number's bound: far beyond any use (degrees, scene radii, seconds, counts), and well
// inside float's and int32's range.
constexpr double kLargest = 1e9;
constexpr const char* kKeys[] = {"s", "space", "1",    "2",     "3", "4",
                                 "5", "6",     "plus", "minus", "f", "escape"};
// A word of the script as an error message quotes it: bytes that are not printable ASCII (a NUL
// would end the message early) become '?'.
std::string printable(std::string word) {
  for (char& ch : word)
    if (ch < 0x20 || ch > 0x7e) ch = '?';
  return word;
}
}  // namespace

std::vector<ScriptCommand> readViewerScript(const std::string& path,
                                            const std::vector<std::string>& modes) {
  if (auto problem = inputFileProblem(path)) throw InputError(path + ": " + *problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the viewer script");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return parseViewerScript(text, path, modes);
}

std::vector<ScriptCommand> parseViewerScript(const std::string& text, const std::string& path,
                                             const std::vector<std::string>& modes) {
  std::istringstream in(text);
  std::vector<ScriptCommand> out;
  std::string raw;
  for (int lineNo = 1; std::getline(in, raw); ++lineNo) {
    const std::string where = path + ":" + std::to_string(lineNo) + ": ";
    std::istringstream line(raw.substr(0, raw.find('#')));
    ScriptCommand c;
    c.line = lineNo;
    if (!(line >> c.name)) continue;
    const Syntax* syntax = nullptr;
    for (const Syntax& s : kSyntax)
      if (c.name == s.name) syntax = &s;
    if (!syntax) throw InputError(where + "unknown command '" + printable(c.name) + "'");
    for (int i = 0; i < syntax->numbers; ++i) {
      std::string word;
      if (!(line >> word))
        throw InputError(where + c.name + " needs " + std::to_string(syntax->numbers) +
                         " number(s)");
      char* end = nullptr;
      const double x = std::strtod(word.c_str(), &end);
      // The whole word (a NUL inside it would end the C string early), and a number the viewer
      // can use: it turns these into floats (1e39 would be infinite) and counts into integers.
      if (end != word.c_str() + word.size() || !std::isfinite(x))
        throw InputError(where + c.name + ": '" + printable(word) + "' is not a number");
      if (std::fabs(x) > kLargest)
        throw InputError(where + c.name + ": " + printable(word) + " is out of range (at most " +
                         std::to_string(int(kLargest)) + " in size)");
      c.numbers.push_back(x);
    }
    if (syntax->text && !(line >> c.text)) throw InputError(where + c.name + " needs an argument");
    std::string extra;
    if (line >> extra)
      throw InputError(where + "unexpected '" + printable(extra) + "' after " + c.name);
    if (c.name == "key") {
      bool known = false;
      for (const char* k : kKeys) known |= c.text == k;
      if (!known)
        throw InputError(where + "unknown key '" + printable(c.text) +
                         "' (s, space, 1-6, plus, minus, f, escape)");
    }
    if (c.name == "mode" && std::find(modes.begin(), modes.end(), c.text) == modes.end()) {
      std::string known;
      for (const std::string& m : modes) known += (known.empty() ? "" : ", ") + m;
      throw InputError(where + "unknown mode '" + c.text + "' (" + known + ")");
    }
    if ((c.name == "wait" || c.name == "at") && c.numbers[0] < 0)
      throw InputError(where + c.name + " needs a time >= 0");
    if (c.name == "zoom" && !(c.numbers[0] >= 1e-6))
      throw InputError(where + "zoom needs a factor > 0 (at least 0.000001)");
    if (c.name == "resize" &&
        (c.numbers[0] < 64 || c.numbers[1] < 64 || c.numbers[0] > 8192 || c.numbers[1] > 8192))
      throw InputError(where + "resize needs a size in [64, 8192]");
    if ((c.name == "camera" || c.name == "wait-units") &&
        (c.numbers[0] < 0 || c.numbers[0] != std::floor(c.numbers[0])))
      throw InputError(where + c.name + " needs a whole number >= 0");
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace osr::viewer
