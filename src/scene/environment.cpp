// Equirectangular environment maps: .exr through OpenEXR, .hdr through stb_image, and the
// importance-sampling CDFs for the device.
#include "scene/environment.h"

#include <ImfArray.h>
#include <ImfRgbaFile.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <vector>

#include "common/error.h"
#include "common/exr_header.h"
#include "common/hdr_check.h"
#include "common/input_file.h"

namespace osr::scene {

namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

Environment loadEnvironment(const std::string& path) {
  if (auto problem = inputFileProblem(path)) throw InputError(path + ": " + *problem);
  Environment env;
  env.path = path;
  std::string ext = lowerExtension(path);
  if (ext == ".exr") {
    if (auto problem = exrHeaderProblem(path)) throw InputError(path + ": " + *problem);
    try {
      Imf::RgbaInputFile file(path.c_str());
      Imath::Box2i dw = file.dataWindow();
      // exrHeaderProblem has refused an empty or vast data window.
      const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
      Imf::Array2D<Imf::Rgba> pixels(h, w);
      // The frame buffer's base is where pixel (0, 0) would be, outside the array for a window
      // far from 0: computed as an integer, since such a pointer is undefined behaviour.
      const uintptr_t base = reinterpret_cast<uintptr_t>(&pixels[0][0]) -
                             uintptr_t(dw.min.x + dw.min.y * w) * sizeof(Imf::Rgba);
      file.setFrameBuffer(reinterpret_cast<Imf::Rgba*>(base), 1, size_t(w));
      file.readPixels(dw.min.y, dw.max.y);
      env.width = uint32_t(w);
      env.height = uint32_t(h);
      env.texels.resize(size_t(w) * h);
      for (long y = 0; y < h; ++y)
        for (long x = 0; x < w; ++x) {
          const Imf::Rgba& p = pixels[y][x];
          env.texels[y * w + x] = glm::vec4(float(p.r), float(p.g), float(p.b), 1.0f);
        }
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError(path + ": cannot read OpenEXR image (" + oneLine(e.what()) + ")");
    }
  } else if (ext == ".hdr") {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open file");
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                           std::istreambuf_iterator<char>());
    // stb_image takes an int size.
    if (bytes.size() >= (size_t(1) << 31)) throw InputError(path + ": larger than 2 GiB, more than osr-vk reads as .hdr");
    const int size = int(bytes.size());
    int w = 0, h = 0, comp = 0;
    if (!stbi_is_hdr_from_memory(bytes.data(), size)) throw InputError(path + ": not a Radiance .hdr image");
    if (auto problem = radianceHdrProblem(bytes.data(), bytes.size())) throw InputError(path + ": " + *problem);
    float* data = stbi_loadf_from_memory(bytes.data(), size, &w, &h, &comp, 3);
    if (!data)
      throw InputError(path + ": cannot read .hdr image (" +
                       std::string(stbi_failure_reason() ? stbi_failure_reason() : "unknown") +
                       ")");
    env.width = uint32_t(w);
    env.height = uint32_t(h);
    env.texels.resize(size_t(w) * h);
    for (size_t i = 0; i < env.texels.size(); ++i)
      env.texels[i] = glm::vec4(data[3 * i], data[3 * i + 1], data[3 * i + 2], 1.0f);
    stbi_image_free(data);
  } else {
    throw InputError(path + ": environment maps must be .exr or .hdr");
  }
  for (glm::vec4& t : env.texels)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(t[k]) || t[k] < 0.0f)
        throw InputError(path + ": environment map holds a negative or non-finite value");
  return env;
}

Environment neutralEnvironment() {
  // A studio's light, white: a soft sky brighter above than below (fill) and a broad key from
  // the front-left above the default camera's three-quarter view (camera.cpp), so that the
  // faces of a box get three different brightnesses. Directions as
  // shaders/lib/scene.glsl environmentDirection().
  constexpr float kPi = 3.14159265f;
  const glm::vec3 key = glm::normalize(glm::vec3(-0.3f, 0.8f, 0.6f));
  Environment env;
  env.width = 128;
  env.height = 64;
  env.texels.resize(size_t(env.width) * env.height);
  for (uint32_t y = 0; y < env.height; ++y)
    for (uint32_t x = 0; x < env.width; ++x) {
      const float phi = ((float(x) + 0.5f) / float(env.width) - 0.5f) * 2.0f * kPi;
      const float theta = (float(y) + 0.5f) / float(env.height) * kPi;
      const glm::vec3 dir(std::sin(theta) * std::cos(phi), std::cos(theta),
                          std::sin(theta) * std::sin(phi));
      const float fill = kNeutralSkyNadir + (kNeutralSkyZenith - kNeutralSkyNadir) * 0.5f * (1.0f + dir.y);
      const float lobe = std::pow(std::max(0.0f, glm::dot(dir, key)), 16.0f);
      const float radiance = fill + kNeutralSkyKey * lobe;
      env.texels[size_t(y) * env.width + x] = glm::vec4(radiance, radiance, radiance, 1.0f);
    }
  return env;
}

std::vector<float> environmentCdf(const Environment& env) {
  const uint32_t w = env.width, h = env.height;
  std::vector<float> cdf;
  if (w == 0 || h == 0) return cdf;
  cdf.resize(size_t(h) + size_t(w) * h);
  std::vector<double> rowWeight(h);
  for (uint32_t y = 0; y < h; ++y) {
    double sum = 0.0;
    for (uint32_t x = 0; x < w; ++x) sum += luminance(glm::vec3(env.texels[size_t(y) * w + x]));
    float* row = &cdf[h + size_t(y) * w];
    double running = 0.0;
    for (uint32_t x = 0; x < w; ++x) {
      running += sum > 0.0 ? luminance(glm::vec3(env.texels[size_t(y) * w + x])) : 1.0;
      row[x] = float(running / (sum > 0.0 ? sum : double(w)));
    }
    row[w - 1] = 1.0f;
    double sinTheta = std::sin((y + 0.5) / h * M_PI);
    rowWeight[y] = sum * sinTheta;
  }
  double total = 0.0;
  for (double r : rowWeight) total += r;
  double running = 0.0;
  for (uint32_t y = 0; y < h; ++y) {
    running += total > 0.0 ? rowWeight[y] : std::sin((y + 0.5) / h * M_PI);
    cdf[y] = float(running);
  }
  for (uint32_t y = 0; y < h; ++y) cdf[y] = float(cdf[y] / running);
  cdf[h - 1] = 1.0f;
  return cdf;
}

}  // namespace osr::scene
