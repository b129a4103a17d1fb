// The scene as loaded from glTF 2.0: flattened into world-space vertices and triangles with
// the device structs of shaders/shared/scene.h, so the upload is a plain copy. Conventions
// (units, extensions, what is unsupported) are those of DESIGN.md "Conventions: Scene".
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scene/animation.h"
#include "shaders/shared/scene.h"

namespace osr::scene {

namespace gpu = osr::gpu::scene;

// One texture: RGBA8 texels, R in the low byte, row 0 first (glTF's uv (0,0) is its top-left).
struct Texture {
  uint32_t width = 0, height = 0;
  uint32_t wrap = 0;  // kWrap* for S in bits 0-1, T in bits 2-3, | kTextureNearest
  std::vector<uint32_t> texels;
  std::string name;
};

// A perspective camera. It looks down its local -Z with +Y up (glTF); worldFromCamera is
// rigid (scale removed). yfov in radians; aspect = width / height, 0 when the file gives none.
struct Camera {
  std::string name;
  int fileIndex = -1;  // index in the glTF file's cameras; -1 for a camera made up here
  glm::mat4 worldFromCamera{1.0f};
  float yfov = 0.8f;
  float aspect = 0.0f;
  // The film as a window of a larger image (--crop; shared/camera.h CameraFrame): the render's
  // width x height pixels are those at (x, y) of an imageWidth x imageHeight image. 0 x 0:
  // the film is the whole image.
  struct Window {
    uint32_t x = 0, y = 0, imageWidth = 0, imageHeight = 0;
  } window;
};

// Equirectangular environment: linear RGB radiance, row 0 at the top (+Y), see
// shaders/lib/scene.glsl environmentDirection() for the direction <-> texel mapping.
struct Environment {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> texels;
  std::string path;
};

struct Scene {
  std::string path;
  std::vector<std::string> files;  // path, then every external buffer and image it reads
  // World space; uv is TEXCOORD_0 with the material's KHR_texture_transform applied.
  std::vector<gpu::Vertex> vertices;
  // Parallel to vertices where some primitive has COLOR_0 or TEXCOORD_1, else empty.
  std::vector<gpu::VertexAttributes> attributes;
  std::vector<gpu::Triangle> triangles;
  std::vector<gpu::Material> materials;  // always >= 1: the last one may be the default
  std::vector<Texture> textures;
  std::vector<gpu::PunctualLight> lights;
  std::vector<gpu::EmissiveTriangle> emissive;  // cdf over power
  std::vector<Camera> cameras;                  // file cameras in node order
  struct SkippedCamera {
    int fileIndex;
    std::string type;  // e.g. "orthographic"
  };
  std::vector<SkippedCamera> skippedCameras;  // file cameras osr-vk cannot render
  glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
  std::vector<std::string> warnings;  // e.g. unsupported extensions (also printed once each)
  float emissivePower = 0.0f;         // sum of emissive[i].power
  // The file's animations and what they move (empty when it has none): poseScene() in
  // scene/animation.h rewrites the parts above that lie under animated nodes.
  Animation animation;
};

// The glTF default material (white, metallic 1, roughness 1 per the spec's factor defaults,
// KHR_* defaults).
gpu::Material defaultMaterial();

// Loads a .gltf or .glb file. Throws InputError("<path>: <problem>") for anything that is not a
// valid glTF 2.0 scene with at least one triangle. Warnings go to Scene::warnings and stderr.
Scene loadScene(const std::string& path);

// Loads an equirectangular .exr (OpenEXR, RGB(A)) or .hdr (Radiance, via stb_image).
// Throws InputError("<path>: <problem>").
Environment loadEnvironment(const std::string& path);

// The light of a scene that has none (no emissive surfaces, no punctual lights, no --env),
// white so that it adds no colour cast: a sky of radiance kNeutralSkyNadir below rising to
// kNeutralSkyZenith above, plus a broad key light (cos^16 lobe of peak kNeutralSkyKey) from the
// upper front-left, so that form shows by shading. path is "" (made up, not read).
inline constexpr float kNeutralSkyNadir = 0.2f, kNeutralSkyZenith = 0.6f, kNeutralSkyKey = 6.0f;
Environment neutralEnvironment();

// Whether the scene emits light by itself (emissive surfaces or punctual lights).
inline bool hasLights(const Scene& s) { return !s.lights.empty() || !s.emissive.empty(); }

// selector "" picks the first file camera, or when there is none a camera framing the scene
// bounds for an image of the given aspect (width / height; <= 0 means 1); a number picks a
// file camera by its index in the file's cameras (as the loader's warnings number them);
// anything else by name. Throws InputError naming the scene file.
Camera selectCamera(const Scene& scene, const std::string& selector, float aspect);

// A three-quarter view of the bounds' centre: from the front-right (+Z, +X) and above, so
// that the front, a side and the top of a box all show; far enough for the bounding sphere to
// fit the smaller field of view of an image with this aspect.
Camera defaultCamera(const Scene& scene, float aspect);

// worldFromNode with its axes scaled to unit length (cameras ignore a node's scale); nullopt
// when an axis has zero or non-finite length.
std::optional<glm::mat4> rigidTransform(const glm::mat4& worldFromNode);

// Sets a punctual light's position and direction (its node's -Z) from its node's transform.
void placeLight(gpu::PunctualLight& light, const glm::mat4& worldFromNode);

// Scene::boundsMin and boundsMax from the vertices.
void updateBounds(Scene& scene);

// Rec. 709 luminance of linear RGB (the weight used for emissive power).
inline float luminance(glm::vec3 c) {
  return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

}  // namespace osr::scene
