// CPU twins of the per-map passes (osr_map_normalize, osr_map_denoise, osr_map_project) and a
// brute-force irradiance, for tests: plain loops over one map at a time, sharing only the
// formulas of shaders/shared/osr.h and the mapping of shaders/shared/hemisphere.h.
#pragma once
#include <array>
#include <glm/glm.hpp>
#include <vector>

#include "osr/osr_settings.h"
#include "shaders/shared/osr.h"

namespace osr::oneshot {

// One-shot map [7][32][32] -> normalized [7][32][32] and its statistics.
std::vector<float> normalizeMapCpu(const float* oneShot, gpu::osr::MapStats& stats);
// Clean radiance [3][32][32] from the one-shot map (blur, none) or the network's output (unet,
// turned into radiance as netOutput, gpu::osr::kNetOutput*, says).
std::vector<float> denoiseMapCpu(Denoiser d, const float* oneShot, const float* netOut,
                                 const gpu::osr::MapStats& stats,
                                 uint32_t netOutput = gpu::osr::kNetOutputRescaled);
// Mean radiance and irradiance SH of a clean map (MapProjection).
void projectMapCpu(const float* clean, glm::vec3& mean, std::array<glm::vec3, 9>& sh);
// Irradiance at local normal n from the projection, as the composite computes it.
glm::vec3 mapIrradianceCpu(const glm::vec3& mean, const std::array<glm::vec3, 9>& sh, glm::vec3 n);
// Irradiance at local normal n by summing the texels (each pi / 1024 of projected solid angle
// around the map's normal), the cosine to n clamped at 0.
glm::vec3 bruteForceIrradiance(const float* clean, glm::vec3 n);

}  // namespace osr::oneshot
