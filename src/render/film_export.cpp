#include "render/film_export.h"

#include <algorithm>

namespace osr::render {

const char* layerName(Layer layer) {
  switch (layer) {
    case Layer::Direct:
      return "direct";
    case Layer::Indirect:
      return "indirect";
    case Layer::Albedo:
      return "albedo";
    case Layer::Normal:
      return "normal";
    case Layer::Depth:
      return "depth";
    case Layer::Combined:
      break;
  }
  return "combined";
}

image::LayeredImage toLayeredImage(const FilmLayers& f) { return toLayeredImage(FilmLayers(f)); }

image::LayeredImage toLayeredImage(FilmLayers&& f) {
  image::LayeredImage img;
  img.width = f.width;
  img.height = f.height;
  const std::vector<std::string> rgb = {"R", "G", "B"}, xyz = {"X", "Y", "Z"};
  img.layers.reserve(9);
  img.layers.push_back({"", rgb, std::move(f.combined)});
  img.layers.push_back({"direct", rgb, std::move(f.direct)});
  img.layers.push_back({"indirect", rgb, std::move(f.indirect)});
  img.layers.push_back({"albedo", rgb, std::move(f.albedo)});
  img.layers.push_back({"normal", xyz, std::move(f.normal)});
  img.layers.push_back({"depth", {"Z"}, std::move(f.depth)});
  // The variance of each pixel's luminance estimate (film.h), what the a-trous filter weighs
  // by and what training data for a denoiser keeps; absent where the integrator has none.
  if (f.variance.size() == size_t(f.width) * size_t(f.height))
    img.layers.push_back({"variance", {"Y"}, std::move(f.variance)});
  // The share of each pixel's camera rays that saw light directly: what the denoisers keep
  // out of their averages, so that a denoiser's training can do the same.
  if (f.light.size() == size_t(f.width) * size_t(f.height))
    img.layers.push_back({"light", {"Y"}, std::move(f.light)});
  // A denoised film keeps its raw colour beside the default (denoised) layer.
  if (!f.noisy.empty()) img.layers.push_back({"noisy", rgb, std::move(f.noisy)});
  return img;
}

image::RgbImage layerImage(const FilmLayers& f, Layer layer) {
  image::RgbImage img{f.width, f.height, {}};
  switch (layer) {
    case Layer::Combined:
      img.rgb = f.combined;
      break;
    case Layer::Direct:
      img.rgb = f.direct;
      break;
    case Layer::Indirect:
      img.rgb = f.indirect;
      break;
    case Layer::Albedo:
      img.rgb = f.albedo;
      break;
    case Layer::Normal:
      img.rgb.resize(f.normal.size());
      std::transform(f.normal.begin(), f.normal.end(), img.rgb.begin(),
                     [](float n) { return 0.5f * n + 0.5f; });
      break;
    case Layer::Depth: {
      float farthest = 0.f;
      for (float d : f.depth) farthest = std::max(farthest, d);
      const float inv = farthest > 0.f ? 1.f / farthest : 0.f;
      img.rgb.resize(f.depth.size() * 3);
      for (size_t i = 0; i < f.depth.size(); ++i)
        img.rgb[3 * i] = img.rgb[3 * i + 1] = img.rgb[3 * i + 2] = f.depth[i] * inv;
      break;
    }
  }
  return img;
}

}  // namespace osr::render
