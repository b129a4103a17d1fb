// Camera choice: a file camera by index or name, or a default one framing the scene.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <glm/gtc/matrix_transform.hpp>

#include "common/error.h"
#include "scene/scene.h"

namespace osr::scene {

std::optional<glm::mat4> rigidTransform(const glm::mat4& worldFromNode) {
  glm::mat4 m = worldFromNode;
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 axis(m[k]);
    const float len = glm::length(axis);
    if (!(len > 0.0f) || !std::isfinite(len)) return std::nullopt;
    m[k] = glm::vec4(axis / len, 0.0f);
  }
  return m;
}

Camera defaultCamera(const Scene& scene, float aspect) {
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;
  Camera cam;
  cam.name = "default";
  cam.yfov = 0.8f;  // ~46 degrees, a normal lens
  cam.aspect = aspect;
  glm::vec3 center = 0.5f * (scene.boundsMin + scene.boundsMax);
  float radius = 0.5f * glm::length(scene.boundsMax - scene.boundsMin);
  if (!(radius > 0.0f)) radius = 1.0f;
  // The bounding sphere must fit the narrower of the two fields of view.
  float halfY = 0.5f * cam.yfov;
  float halfX = std::atan(std::tan(halfY) * aspect);
  float half = std::min(halfX, halfY);
  float distance = radius / std::sin(half) * 1.05f;
  // Three-quarter view: 35 degrees round from +Z towards +X, 25 degrees above the horizon
  // (+Y up, glTF), so depth shows on boxes and faces that a face-on view would flatten.
  const float azimuth = glm::radians(35.0f), elevation = glm::radians(25.0f);
  const glm::vec3 towardsEye(std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
                             std::cos(azimuth) * std::cos(elevation));
  const glm::vec3 eye = center + distance * towardsEye;
  cam.worldFromCamera = glm::inverse(glm::lookAt(eye, center, glm::vec3(0.0f, 1.0f, 0.0f)));
  return cam;
}

Camera selectCamera(const Scene& scene, const std::string& selector, float aspect) {
  if (selector.empty())
    return scene.cameras.empty() ? defaultCamera(scene, aspect) : scene.cameras.front();
  char* end = nullptr;
  errno = 0;
  long index = std::strtol(selector.c_str(), &end, 10);
  if (*end == '\0' && errno == 0) {
    for (const Camera& c : scene.cameras)
      if (c.fileIndex == index) return c;
    std::string usable;
    for (const Camera& c : scene.cameras)
      usable += (usable.empty() ? "" : ", ") + std::to_string(c.fileIndex);
    usable = usable.empty() ? "none" : usable;
    for (const Scene::SkippedCamera& c : scene.skippedCameras)
      if (c.fileIndex == index)
        throw InputError(scene.path + ": camera " + selector + " is " + c.type +
                         ", which osr-vk cannot render (usable cameras: " + usable + ")");
    const size_t count = scene.cameras.size() + scene.skippedCameras.size();
    throw InputError(scene.path + ": camera " + selector + " does not exist (the file has " +
                     (count == 0 ? std::string("no cameras")
                                 : std::to_string(count) + " camera(s); usable: " + usable) +
                     ")");
  }
  for (const Camera& c : scene.cameras)
    if (c.name == selector) return c;
  std::string names;
  for (const Camera& c : scene.cameras) names += (names.empty() ? "" : ", ") + ("'" + c.name + "'");
  throw InputError(scene.path + ": no camera named '" + selector +
                   "' (cameras: " + (names.empty() ? "none" : names) + ")");
}

}  // namespace osr::scene
