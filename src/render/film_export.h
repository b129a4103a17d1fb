// Film layers as image files: the layered OpenEXR (combined as the default RGB layer, then
// direct, indirect, albedo, normal, depth) that --offline writes and the viewer's save button
// writes, and the single layers the viewer shows.
#pragma once
#include <string>

#include "image/image_io.h"
#include "render/film.h"

namespace osr::render {

// The layers a front end can show, in the viewer's key order 1-6.
enum class Layer { Combined, Direct, Indirect, Albedo, Normal, Depth };
inline constexpr int kLayerCount = 6;
const char* layerName(Layer layer);

// Every layer of `film`, named as DESIGN.md's output section fixes.
image::LayeredImage toLayeredImage(const FilmLayers& film);
// The same, taking the film's layers instead of copying them (hundreds of MiB at 4K).
image::LayeredImage toLayeredImage(FilmLayers&& film);

// One layer as RGB for display: colour layers as they are, normals mapped from [-1, 1] to
// [0, 1], depth as grey scaled so the farthest hit is 1.
image::RgbImage layerImage(const FilmLayers& film, Layer layer);

}  // namespace osr::render
