// Environment-map helpers shared by the upload and the tests: the importance-sampling tables
// that shaders/lib/scene.glsl (sampleEnvironment, environmentPdf) reads.
#pragma once
#include <vector>

#include "scene/scene.h"

namespace osr::scene {

// Inclusive CDFs in the layout of the gEnvironmentCdf buffer: height marginal entries over rows
// (weight: row luminance sum x sin(theta) of the row centre), then per row width conditional
// entries over its texels (weight: luminance). Each ends in exactly 1; an all-black row or map
// falls back to uniform weights. Empty for an empty environment.
std::vector<float> environmentCdf(const Environment& env);

}  // namespace osr::scene
