// Image files of osr-vk: multi-layer OpenEXR out (combined RGB as the default layer plus named
// layers), OpenEXR RGB in (for compare and tests), and a tone-mapped 8-bit PNG preview.
// Writers go through a temporary file in the target's directory and a rename, so a failure
// never leaves a half-written file or destroys an existing one.
#pragma once
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

namespace osr::image {

// One layer: `name` "" is the default layer (channels R, G, B); others are written as
// "<name>.<channel>". channelNames has 1 or 3 entries; data is interleaved, row-major,
// top row first: width * height * channelNames.size() floats.
struct ImageLayer {
  std::string name;
  std::vector<std::string> channelNames;
  std::vector<float> data;
};

// A header attribute of an OpenEXR file (written as OpenEXR's int, float or string type).
struct ExrAttribute {
  std::string name;
  std::variant<int, float, std::string> value;
};

struct LayeredImage {
  int width = 0;
  int height = 0;
  std::vector<ImageLayer> layers;
  std::vector<ExrAttribute> attributes;  // extra header attributes (how it was rendered)
};

// RGB float image, interleaved, top row first.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;
  // Rec. 709 luminance of pixel `i` (row-major), in double for the image-wide sums.
  double luminance(size_t i) const {
    return 0.2126 * rgb[3 * i] + 0.7152 * rgb[3 * i + 1] + 0.0722 * rgb[3 * i + 2];
  }
};

enum class ExrPixelType { Half, Float };

// Throws InputError ("<path>: ...") when the file cannot be written.
void writeExr(const std::string& path, const LayeredImage& image, ExrPixelType type);
// Reads the default layer's R, G, B (or Y as grey), or those of `layer` ("noisy" reads
// noisy.R, noisy.G, noisy.B). Throws InputError naming the file, also for a header that
// OpenEXR must not open and an empty or vast data window (common/exr_header.h).
RgbImage readExrRgb(const std::string& path, const std::string& layer = "");
// The names of the file's channels ("R", "variance.Y", ...). Throws InputError naming the file.
std::set<std::string> exrChannels(const std::string& path);
// The header's int, float and string attributes (others are left out), in the header's order.
// Throws InputError naming the file.
std::vector<ExrAttribute> readExrAttributes(const std::string& path);

// Writes `bytes` to `path` as the image writers do: into a temporary beside it, renamed over
// `path` when complete, so a reader (or a signal) never finds half a file. Throws InputError
// ("<path>: cannot write (...)").
void writeFileAtomic(const std::string& path, const void* data, size_t bytes);

// The temporary file a writer of this module has open (it becomes the output by a rename
// when complete), or null: a signal handler that exits at once unlinks it, so no half file
// is left behind. Async-signal-safe.
const char* pendingTempFile();

// Automatic exposure (EV). It meters the pixels that saw a surface (depth[i] > 0, where a
// depth layer is given; e.g. render::FilmLayers::depth) or carry light (luminance > 0), so a
// black background does not count: a small object on black is exposed for the object. The
// metered luminance is the mean over those pixels, each clipped at kMeterClipOverMedian times
// the median of the lit ones (visible lights and fireflies do not darken the image), and the
// exposure maps it to kExposureKey. A mean, not a log-average, because a 1-spp render's
// metered pixels are mostly 0 or a few times too bright: their mean is the converged image's
// (the estimate is unbiased), their log-average is not. 0 EV when nothing is lit.
inline constexpr double kMeterClipOverMedian = 8.0;
inline constexpr double kExposureKey = 0.18;
double meteredLuminance(const RgbImage& image, const std::vector<float>& depth = {});
double autoExposureEv(const RgbImage& image, const std::vector<float>& depth = {});
// How exposed linear values above 1 are brought into [0, 1] before the sRGB OETF.
enum class ToneMap {
  Clamp,     // clamp(x, 0, 1): the default; what the seed's PNGs did
  Reinhard,  // x / (1 + x) per channel (Reinhard et al. 2002)
  Aces,      // Narkowicz 2015's fit of the ACES filmic curve
};
const char* toneMapName(ToneMap op);
// Interleaved 8-bit sRGB of `image` exposed by 2^exposureEv and tone mapped by `op`;
// non-finite values become 0. What writePng writes and the viewer shows.
std::vector<uint8_t> toneMapSrgb8(const RgbImage& image, double exposureEv,
                                  ToneMap op = ToneMap::Clamp);
// PNG preview: toneMapSrgb8 of the image; autoExposureEv(image, depth) when ev is empty.
void writePng(const std::string& path, const RgbImage& image, std::optional<double> exposureEv,
              const std::vector<float>& depth = {}, ToneMap op = ToneMap::Clamp);
// PNG of interleaved 8-bit sRGB (width * height * 3 bytes), e.g. a viewer screenshot.
void writePng8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

// Whether `path` holds a whole image: an OpenEXR (.exr) whose pixels all read, or a PNG (.png)
// that decodes; false for a missing, truncated or corrupt file (osr-vk --resume skips a frame
// only when this holds for each of its outputs).
bool isCompleteImage(const std::string& path);

// Fails early (InputError) if `path` cannot be created: its directory is missing or not
// writable, or the path is a directory. Leaves no file behind.
void checkWritable(const std::string& path);

}  // namespace osr::image
