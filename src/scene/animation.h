// glTF animations of rigid node transforms, and the scene posed at a time. The loader reads the
// file's samplers and records what the animated nodes carry (meshes in object space, cameras,
// lights); poseScene() re-evaluates the node hierarchy at time t and rewrites those parts of
// the flattened world-space Scene. Sampling follows the glTF 2.0 spec, Appendix C: STEP holds
// a key, LINEAR interpolates (rotations by slerp on the shorter arc), CUBICSPLINE is the
// Hermite spline over each key's in-tangent, value and out-tangent; before the first key and
// after the last, the end keys hold. Skins and morph-target weights are not animated (the
// loader warns). Every animation in the file plays at once on one clock, as on Blender's
// timeline, which exports one glTF animation per animated object.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "shaders/shared/scene.h"

namespace osr::scene {

struct Scene;

enum class Interpolation { Step, Linear, CubicSpline };
enum class TrsPath { Translation, Rotation, Scale };

// One animated property of one node. Rotations are quaternions as (x, y, z, w) in a vec4, as
// glTF stores them; translations and scales use xyz.
struct AnimationChannel {
  int node = -1;
  TrsPath path = TrsPath::Translation;
  Interpolation interpolation = Interpolation::Linear;
  std::vector<float> times;       // seconds, non-decreasing, at least one
  std::vector<glm::vec4> values;  // one per key; CUBICSPLINE: three (in-tangent, value, out)
};

// A node's local transform: a matrix (never animated, per the spec) or translation, rotation,
// scale, composed as T * R * S.
struct NodePose {
  bool hasMatrix = false;
  glm::mat4 matrix{1.0f};
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // glm order: (w, x, y, z)
  glm::vec3 scale{1.0f};
  glm::mat4 local() const;
};

// The value of `channel` at time `t` (seconds): vec4 for rotations (normalized), xyz else.
glm::vec4 sampleChannel(const AnimationChannel& channel, double t);

// A mesh primitive under a moving node: where its world-space copy lies in Scene::vertices and
// Scene::triangles, and the object-space data to transform again. A primitive without normals
// is flat shaded: three vertices per triangle carrying the face normal, recomputed each pose.
struct MovingPrimitive {
  int node = -1;
  uint32_t firstVertex = 0, firstTriangle = 0, triangleCount = 0;
  bool flatShaded = false;
  bool mirrored = false;  // the winding in Scene::triangles is flipped (det < 0 when posed)
  std::vector<glm::vec3> positions;  // object space, one per vertex from firstVertex
  std::vector<glm::vec3> normals;    // object space (smooth shading only)
};

struct Animation {
  std::vector<AnimationChannel> channels;
  // Every node the default scene reaches, parents before children (-1: a root), with its rest
  // pose; nodes outside the default scene have parent -1 and are never posed.
  std::vector<int> order;  // node indices, parents first
  std::vector<int> parent;
  std::vector<NodePose> rest;
  std::vector<bool> moving;  // the node or an ancestor is the target of a channel
  std::vector<MovingPrimitive> primitives;
  std::vector<int> cameraNodes;  // per Scene::cameras entry, the node that carries it
  std::vector<int> lightNodes;   // per Scene::lights entry, the node that carries it
  float startS = 0.0f, endS = 0.0f;  // first and last key time over all channels

  bool empty() const { return channels.empty(); }
  // What posing changes: cameras only (the BVH stays), or lights and geometry too.
  bool movesCameras() const;
  bool movesGeometry() const;  // meshes or lights
};

// A mesh primitive that one poseScene call moved: its world bounds at the pose before and at
// the new one, and whether it emits light (some triangle's material has emission).
struct MovedPrimitive {
  glm::vec3 beforeLo{0.0f}, beforeHi{0.0f}, afterLo{0.0f}, afterHi{0.0f};
  bool emissive = false;
};

// What poseScene changed. The flags say what lies under an animated node and was rewritten
// (what a device scene must upload again); `moved` and `lightMoved` what did move since the
// pose before (the last poseScene call, or the file's rest pose), for caches of light
// (OSR's map cache keeps the maps away from what moved).
struct PoseChange {
  bool cameras = false;
  bool lights = false;
  bool geometry = false;  // vertices (and so triangles' winding, emissive, bounds)
  std::vector<MovedPrimitive> moved;  // primitives with a vertex that changed position
  bool lightMoved = false;            // a punctual light's position or direction changed
};

// Poses `scene` at time t (seconds): node transforms from scene.animation, then the vertices of
// moving meshes, the cameras and lights under moving nodes, the emissive triangles and bounds.
// Only what lies under an animated node is rewritten. A scene without animation is unchanged.
PoseChange poseScene(Scene& scene, double t);

}  // namespace osr::scene
