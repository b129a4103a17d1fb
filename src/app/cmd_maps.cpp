// osr-vk maps scene.gltf --out DIR: hemisphere maps at chosen pixels of one or more jittered
// views, for training data (DESIGN.md "Training data"): the one-shot input the renderer feeds
// its network and, with --reference-spp, many-path reference radiance of the same points.
// Writes input.npy, target.npy, points.npy and index.json (docs/maps_format.md). Every
// argument is checked before any work, and every file is written under a temporary name and
// renamed once all are complete, so a failure leaves no half file.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "app/commands.h"
#include "app/maps_options.h"
#include "app/npy.h"
#include "app/scene_setup.h"
#include "common/error.h"
#include "nn_kernels/weights_format.h"
#include "osr/map_tracer.h"
#include "shaders/shared/scene.h"

namespace osr::app {

namespace {

namespace fs = std::filesystem;

constexpr size_t kTexels = gpu::hemi::kMapTexels;
constexpr size_t kMapFloats = size_t(gpu::osr::kMapChannels) * kTexels;

uint32_t hash32(uint32_t x) { return gpu::scene::sceneHash(x); }  // lowbias32 (Wellons)

// One pixel per r x r cell of the image (edge cells clipped), placed by a hash of the seed,
// view and cell, so the same arguments give the same points.
std::vector<glm::uvec2> jitteredGrid(uint32_t width, uint32_t height, uint32_t r, uint32_t seed,
                                     uint32_t view) {
  std::vector<glm::uvec2> pixels;
  for (uint32_t y0 = 0; y0 < height; y0 += r)
    for (uint32_t x0 = 0; x0 < width; x0 += r) {
      uint32_t h = hash32(seed ^ hash32(view ^ hash32(x0 ^ hash32(y0 + 0x9e3779b9u))));
      const uint32_t cw = std::min(r, width - x0), ch = std::min(r, height - y0);
      pixels.emplace_back(x0 + h % cw, y0 + hash32(h) % ch);
    }
  return pixels;
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += char(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += char(c);
    }
  }
  return out + "\"";
}

std::string jsonNames(const std::vector<const char*>& names) {
  std::string out = "[";
  for (size_t i = 0; i < names.size(); ++i) out += (i ? ", \"" : "\"") + std::string(names[i]) + "\"";
  return out + "]";
}

// Files written under temporary names in the output folder, renamed together by commit();
// the destructor removes whatever was not committed (and the folder, if it made it and it
// is still empty).
class OutputFiles {
 public:
  explicit OutputFiles(fs::path dir) : dir_(std::move(dir)) {
    std::error_code ec;
    createdDir_ = fs::create_directories(dir_, ec);
    if (ec || !fs::is_directory(dir_))
      throw InputError("--out: cannot create folder " + dir_.string() +
                       (ec ? ": " + ec.message() : std::string()));
  }
  ~OutputFiles() {
    std::error_code ec;
    for (const auto& [tmp, final] : files_) fs::remove(tmp, ec);
    if (createdDir_ && !committed_) fs::remove(dir_, ec);  // only removes an empty folder
  }
  // A temporary path for the file `name`, renamed to DIR/name by commit().
  std::string add(const std::string& name) {
    fs::path tmp = dir_ / ("." + name + ".tmp" + std::to_string(::getpid()));
    files_.emplace_back(tmp, dir_ / name);
    return tmp.string();
  }
  void commit() {
    for (const auto& [tmp, final] : files_) fs::rename(tmp, final);
    files_.clear();
    committed_ = true;
  }
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
  std::vector<std::pair<fs::path, fs::path>> files_;
  bool createdDir_ = false, committed_ = false;
};

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int runMaps(const std::vector<std::string>& args) {
  const MapsOptions o = parseMapsOptions(args);
  const std::vector<glm::uvec2>& listed = o.pixels;
  const uint32_t referenceSpp = o.referenceSpp, views = o.views, seed = o.seed;
  const bool quiet = o.quiet;
  const HostScene host = loadHostScene(o.scenePath, o.scene);
  for (const glm::uvec2& p : listed)
    if (p.x >= host.width || p.y >= host.height)
      throw InputError("--pixels: " + std::to_string(p.x) + "," + std::to_string(p.y) +
                       " is outside the " + std::to_string(host.width) + "x" +
                       std::to_string(host.height) + " image");
  warnIfNeutralSky(host);

  vk::Context ctx(o.device);
  const DeviceScene dev(ctx, host);
  OutputFiles out(o.outDir);
  oneshot::MapTracer tracer(ctx, dev.gpu, dev.bvh, host.camera, host.width, host.height, seed);

  std::vector<float> input, target;
  std::vector<int32_t> points;
  double inputS = 0.0, referenceS = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  for (uint32_t v = 0; v < views; ++v) {
    tracer.setView(v);
    const std::vector<gpu::osr::GBufferPixel> gb = tracer.gbuffer();
    std::vector<glm::uvec2> pixels;
    for (const glm::uvec2& p : o.grid ? jitteredGrid(host.width, host.height, uint32_t(*o.grid), seed, v)
                                    : listed)
      if (gb[size_t(p.y) * host.width + p.x].position.w >= 0.5f) pixels.push_back(p);
    if (pixels.empty()) continue;
    auto t = std::chrono::steady_clock::now();
    std::vector<float> maps = tracer.trace(pixels, 1, 2 * v);
    inputS += secondsSince(t);
    input.insert(input.end(), maps.begin(), maps.end());
    if (referenceSpp > 0) {
      t = std::chrono::steady_clock::now();
      maps = tracer.trace(pixels, referenceSpp, 2 * v + 1);
      referenceS += secondsSince(t);
      for (size_t m = 0; m < pixels.size(); ++m)  // radiance RGB: the first 3 channels
        target.insert(target.end(), maps.begin() + m * kMapFloats,
                      maps.begin() + m * kMapFloats + 3 * kTexels);
    }
    for (const glm::uvec2& p : pixels) points.insert(points.end(), {int32_t(v), int32_t(p.x), int32_t(p.y)});
    if (!quiet)
      std::fprintf(stderr, "osr-vk: maps: view %u/%u, %zu maps, %.1f s\n", v + 1, views,
                   points.size() / 3, secondsSince(t0));
  }

  const uint64_t count = points.size() / 3;
  npy::write(out.add("input.npy"), "<f4", {count, gpu::osr::kMapChannels, 32, 32}, input.data(),
             input.size() * sizeof(float));
  if (referenceSpp > 0)
    npy::write(out.add("target.npy"), "<f4", {count, 3, 32, 32}, target.data(),
               target.size() * sizeof(float));
  npy::write(out.add("points.npy"), "<i4", {count, 3}, points.data(), points.size() * sizeof(int32_t));

  std::ostringstream j;
  j << "{\n  \"format\": \"osr-vk maps\",\n  \"version\": " << jsonString(kVersion)
    << ",\n  \"scene\": " << jsonString(o.scenePath) << ",\n  \"camera\": " << jsonString(host.camera.name)
    << ",\n  \"width\": " << host.width << ",\n  \"height\": " << host.height
    << ",\n  \"seed\": " << seed << ",\n  \"views\": " << views << ",\n  \"grid\": ";
  if (o.grid) j << *o.grid;
  else j << "null";
  j << ",\n  \"pixels\": ";
  if (o.pixelText) {
    j << "[";
    for (size_t i = 0; i < listed.size(); ++i)
      j << (i ? ", [" : "[") << listed[i].x << ", " << listed[i].y << "]";
    j << "]";
  } else {
    j << "null";
  }
  j << ",\n  \"reference_spp\": " << referenceSpp << ",\n  \"input_paths_per_texel\": 1"
    << ",\n  \"count\": " << count << ",\n  \"map_size\": 32,\n  \"mapping\": "
    << jsonString(nn::kMappingConcentric) << ",\n  \"input_channels\": "
    << jsonNames({"radiance_r", "radiance_g", "radiance_b", "normal_x", "normal_y", "normal_z",
                  "distance"})
    << ",\n  \"target_channels\": "
    << (referenceSpp > 0 ? jsonNames({"radiance_r", "radiance_g", "radiance_b"}) : "null")
    << ",\n  \"points_columns\": " << jsonNames({"view", "x", "y"})
    << ",\n  \"files\": "
    << (referenceSpp > 0 ? jsonNames({"input.npy", "target.npy", "points.npy"})
                         : jsonNames({"input.npy", "points.npy"}))
    << "\n}\n";
  {
    const std::string path = out.add("index.json");
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f << j.str();
    f.close();
    if (!f) throw std::runtime_error(path + ": cannot write");
  }
  // A target.npy of an earlier run without a reference would no longer match input.npy.
  if (referenceSpp == 0) fs::remove(out.dir() / "target.npy");
  out.commit();
  if (!quiet) {
    std::fprintf(stderr, "osr-vk: maps: %llu maps in %s, one-shot %.2f s (%.1f maps/s)",
                 static_cast<unsigned long long>(count), out.dir().c_str(), inputS,
                 inputS > 0 ? count / inputS : 0.0);
    if (referenceSpp > 0)
      std::fprintf(stderr, ", reference %u spp %.2f s (%.1f maps/s)", referenceSpp, referenceS,
                   referenceS > 0 ? count / referenceS : 0.0);
    std::fputc('\n', stderr);
  }
  return 0;
}

}  // namespace osr::app
