// Emissive triangles for light sampling: every triangle whose material emits, with its power,
// so that a light is chosen with probability power / total (Scene::emissive, the cdf over it).
#pragma once
#include "scene/scene.h"

namespace osr::scene {

// Fills scene.emissive and scene.emissivePower from triangles, vertices, materials and
// textures. Power = luminance(emission x mean linear emissive texture) x area x pi, doubled
// for double-sided materials (both sides emit); zero-area and non-emitting triangles are left
// out. The cdf is inclusive and ends in exactly 1.
void collectEmissive(Scene& scene);

}  // namespace osr::scene
