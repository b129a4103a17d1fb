#include "scene/animation.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <optional>

#include "scene/emissive.h"
#include "scene/scene.h"

namespace osr::scene {

glm::mat4 NodePose::local() const {
  if (hasMatrix) return matrix;
  const glm::mat4 t = glm::translate(glm::mat4(1.0f), translation);
  const glm::mat4 s = glm::scale(glm::mat4(1.0f), scale);
  return t * glm::mat4_cast(rotation) * s;
}

namespace {

glm::quat toQuat(glm::vec4 xyzw) { return glm::quat(xyzw.w, xyzw.x, xyzw.y, xyzw.z); }

glm::vec4 normalizedRotation(glm::vec4 q) {
  const float len = glm::length(q);
  return len > 0.0f && std::isfinite(len) ? q / len : glm::vec4(0, 0, 0, 1);
}

// The glTF spec's slerp (Appendix C): the shorter arc (b negated when the dot is negative),
// linear interpolation where the quaternions are nearly parallel.
glm::vec4 slerp(glm::vec4 a, glm::vec4 b, float u) {
  float d = glm::dot(a, b);
  if (d < 0.0f) {
    b = -b;
    d = -d;
  }
  if (d > 0.9995f) return normalizedRotation(glm::mix(a, b, u));
  const float angle = std::acos(std::min(d, 1.0f));
  const float s = std::sin(angle);
  return normalizedRotation((std::sin((1.0f - u) * angle) / s) * a + (std::sin(u * angle) / s) * b);
}

}  // namespace

glm::vec4 sampleChannel(const AnimationChannel& c, double t) {
  const bool cubic = c.interpolation == Interpolation::CubicSpline;
  const bool rotation = c.path == TrsPath::Rotation;
  // Key k's value: the middle of its three elements for CUBICSPLINE.
  auto value = [&](size_t k) { return c.values[cubic ? 3 * k + 1 : k]; };
  auto finish = [&](glm::vec4 v) { return rotation ? normalizedRotation(v) : v; };
  const size_t n = c.times.size();
  if (t <= c.times.front()) return finish(value(0));
  if (t >= c.times.back()) return finish(value(n - 1));
  // The last key at or before t: times[k] <= t < times[k + 1].
  const size_t k = size_t(std::upper_bound(c.times.begin(), c.times.end(), float(t)) - c.times.begin()) - 1;
  const double dt = double(c.times[k + 1]) - double(c.times[k]);
  if (c.interpolation == Interpolation::Step || !(dt > 0.0)) return finish(value(k));
  const float u = float((t - c.times[k]) / dt);
  if (c.interpolation == Interpolation::Linear)
    return rotation ? slerp(value(k), value(k + 1), u) : glm::mix(value(k), value(k + 1), u);
  // Hermite basis; the tangents are per second, so they scale by the interval.
  const float u2 = u * u, u3 = u2 * u, d = float(dt);
  const glm::vec4 outTangent = c.values[3 * k + 2], inTangent = c.values[3 * (k + 1)];
  return finish((2 * u3 - 3 * u2 + 1) * value(k) + d * (u3 - 2 * u2 + u) * outTangent +
                (-2 * u3 + 3 * u2) * value(k + 1) + d * (u3 - u2) * inTangent);
}

bool Animation::movesCameras() const {
  for (int node : cameraNodes)
    if (node >= 0 && moving[node]) return true;
  return false;
}

bool Animation::movesGeometry() const {
  if (!primitives.empty()) return true;
  for (int node : lightNodes)
    if (node >= 0 && moving[node]) return true;
  return false;
}

namespace {

// World transforms of every node at time t (identity for nodes outside the default scene).
std::vector<glm::mat4> worldTransforms(const Animation& a, double t) {
  std::vector<NodePose> pose = a.rest;
  for (const AnimationChannel& c : a.channels) {
    const glm::vec4 v = sampleChannel(c, t);
    NodePose& p = pose[c.node];
    if (c.path == TrsPath::Translation) p.translation = glm::vec3(v);
    if (c.path == TrsPath::Rotation) p.rotation = toQuat(v);
    if (c.path == TrsPath::Scale) p.scale = glm::vec3(v);
  }
  std::vector<glm::mat4> world(a.rest.size(), glm::mat4(1.0f));
  for (int node : a.order) {
    const glm::mat4 parent = a.parent[node] >= 0 ? world[a.parent[node]] : glm::mat4(1.0f);
    world[node] = parent * pose[node].local();
  }
  return world;
}

// Poses one primitive; returns its bounds before and after when a vertex moved.
std::optional<MovedPrimitive> posePrimitive(Scene& scene, MovingPrimitive& p,
                                            const glm::mat4& worldFromObject) {
  const glm::mat3 linear(worldFromObject);
  const bool mirrored = glm::determinant(linear) < 0.0f;
  gpu::Triangle* triangles = scene.triangles.data() + p.firstTriangle;
  // Counter-clockwise front faces stay so under a mirroring transform (as the loader does).
  if (mirrored != p.mirrored)
    for (uint32_t i = 0; i < p.triangleCount; ++i) std::swap(triangles[i].v1, triangles[i].v2);
  p.mirrored = mirrored;
  gpu::Vertex* vertices = scene.vertices.data() + p.firstVertex;
  MovedPrimitive moved;
  moved.beforeLo = moved.afterLo = glm::vec3(INFINITY);
  moved.beforeHi = moved.afterHi = glm::vec3(-INFINITY);
  bool changed = false;
  for (size_t i = 0; i < p.positions.size(); ++i) {
    const glm::vec3 before = vertices[i].position;
    const glm::vec3 after = glm::vec3(worldFromObject * glm::vec4(p.positions[i], 1.0f));
    changed = changed || before != after;
    moved.beforeLo = glm::min(moved.beforeLo, before);
    moved.beforeHi = glm::max(moved.beforeHi, before);
    moved.afterLo = glm::min(moved.afterLo, after);
    moved.afterHi = glm::max(moved.afterHi, after);
    vertices[i].position = after;
  }
  for (uint32_t i = 0; i < p.triangleCount && !moved.emissive; ++i)
    moved.emissive = luminance(scene.materials[triangles[i].material].emission) > 0.0f;
  const std::optional<MovedPrimitive> result =
      changed ? std::optional<MovedPrimitive>(moved) : std::nullopt;
  if (p.flatShaded) {
    for (uint32_t i = 0; i < p.triangleCount; ++i) {
      const gpu::Triangle& t = triangles[i];
      gpu::Vertex* v[3] = {&scene.vertices[t.v0], &scene.vertices[t.v1], &scene.vertices[t.v2]};
      glm::vec3 n = glm::cross(v[1]->position - v[0]->position, v[2]->position - v[0]->position);
      const float len = glm::length(n);
      n = len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0.0f);
      for (gpu::Vertex* vertex : v) vertex->normal = n;
    }
    return result;
  }
  const glm::mat3 normalFromObject = glm::transpose(glm::inverse(linear));
  for (size_t i = 0; i < p.normals.size(); ++i) {
    const glm::vec3 n = normalFromObject * p.normals[i];
    const float len = glm::length(n);
    // As at load: a zero or broken normal falls back to the face normal in the shader.
    vertices[i].normal = len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0.0f);
  }
  return result;
}

}  // namespace

PoseChange poseScene(Scene& scene, double t) {
  Animation& a = scene.animation;
  PoseChange change;
  if (a.empty()) return change;
  const std::vector<glm::mat4> world = worldTransforms(a, t);
  for (size_t i = 0; i < scene.cameras.size() && i < a.cameraNodes.size(); ++i) {
    const int node = a.cameraNodes[i];
    if (node < 0 || !a.moving[node]) continue;
    // A degenerate pose (a camera scaled to zero) keeps the last usable one.
    if (auto rigid = rigidTransform(world[node])) scene.cameras[i].worldFromCamera = *rigid;
    change.cameras = true;
  }
  for (size_t i = 0; i < scene.lights.size() && i < a.lightNodes.size(); ++i) {
    const int node = a.lightNodes[i];
    if (node < 0 || !a.moving[node]) continue;
    const gpu::PunctualLight before = scene.lights[i];
    placeLight(scene.lights[i], world[node]);
    change.lights = true;
    change.lightMoved = change.lightMoved || before.position != scene.lights[i].position ||
                        before.direction != scene.lights[i].direction;
  }
  for (MovingPrimitive& p : a.primitives)
    if (auto moved = posePrimitive(scene, p, world[p.node])) change.moved.push_back(*moved);
  if (!a.primitives.empty()) {
    change.geometry = true;
    updateBounds(scene);
    collectEmissive(scene);
  }
  return change;
}

}  // namespace osr::scene
