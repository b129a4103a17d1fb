// Emissive triangles for light sampling: every triangle whose material emits, with its power,
// so that a light is chosen with probability power / total (Scene::emissive, the cdf over it).
#pragma once
#include "scene/scene.h"

namespace osr::scene {

// Fills scene.emissive and scene.emissivePower from triangles, vertices, materials and
// textures. Power = luminance(mean emitted radiance over the triangle) x area x pi, doubled
// for double-sided materials (both sides emit), the mean taken over the triangle's own part
// of its emissive texture and coverage (emissive.cpp meanEmission); zero-area and
// non-emitting triangles are left out. The cdf is inclusive and ends in exactly 1.
void collectEmissive(Scene& scene);

}  // namespace osr::scene
