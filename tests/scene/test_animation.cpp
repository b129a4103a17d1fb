// glTF animation: each sampler kind against hand-computed values (glTF 2.0 spec, Appendix C),
// and the scene posed at a time (tests/data/scene/animated.gltf, written by
// tools/make_scene_test_data.py): moving meshes, their children, mirrored winding, cameras.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/test_paths.h"
#include "scene/animation.h"
#include "scene/scene.h"
#include "scene/scene_test_util.h"

using namespace osr;
using test::expectNear;

namespace {

scene::AnimationChannel channel(scene::TrsPath path, scene::Interpolation interpolation,
                                std::vector<float> times, std::vector<glm::vec4> values) {
  scene::AnimationChannel c;
  c.node = 0;
  c.path = path;
  c.interpolation = interpolation;
  c.times = std::move(times);
  c.values = std::move(values);
  return c;
}

void expectNear4(glm::vec4 a, glm::vec4 b, float tol = 1e-5f) {
  EXPECT_LE(glm::length(a - b), tol) << "(" << a.x << ", " << a.y << ", " << a.z << ", " << a.w
                                     << ") vs (" << b.x << ", " << b.y << ", " << b.z << ", "
                                     << b.w << ")";
}

// animated.gltf's vertices and triangles, in the loader's node order (stepper, spinner, its
// child rider, bouncer, flipper, still): four per quad, three for the flat triangle.
constexpr uint32_t kStepper = 0, kSpinner = 4, kRider = 8, kBouncer = 12, kFlipper = 16,
                   kStill = 19;
constexpr uint32_t kFlipperTriangle = 8;
const float kH = std::sqrt(0.5f);

scene::Scene loadAnimated() {
  return scene::loadScene(test::dataPath("scene/animated.gltf"));
}

}  // namespace

TEST(Animation, StepHoldsEachKey) {
  auto c = channel(scene::TrsPath::Translation, scene::Interpolation::Step, {0, 1, 2},
                   {{0, 0, 0, 0}, {1, 0, 0, 0}, {3, 0, 0, 0}});
  expectNear4(sampleChannel(c, -1.0), {0, 0, 0, 0});
  expectNear4(sampleChannel(c, 0.99), {0, 0, 0, 0});
  expectNear4(sampleChannel(c, 1.0), {1, 0, 0, 0});
  expectNear4(sampleChannel(c, 1.999), {1, 0, 0, 0});
  expectNear4(sampleChannel(c, 2.0), {3, 0, 0, 0});
  expectNear4(sampleChannel(c, 50.0), {3, 0, 0, 0});
}

TEST(Animation, LinearInterpolatesAndHoldsTheEnds) {
  auto c = channel(scene::TrsPath::Scale, scene::Interpolation::Linear, {1, 3},
                   {{1, 2, 3, 0}, {3, 2, -1, 0}});
  expectNear4(sampleChannel(c, 0.0), {1, 2, 3, 0});
  expectNear4(sampleChannel(c, 1.5), {1.5f, 2, 2, 0});
  expectNear4(sampleChannel(c, 2.0), {2, 2, 1, 0});
  expectNear4(sampleChannel(c, 9.0), {3, 2, -1, 0});
}

TEST(Animation, LinearRotationIsSlerpOnTheShortArc) {
  // 0 to 90 degrees about +Y, the second key given negated (the same rotation): the spec's
  // slerp goes the short way, so a quarter of the interval is 22.5 degrees.
  auto c = channel(scene::TrsPath::Rotation, scene::Interpolation::Linear, {0, 2},
                   {{0, 0, 0, 1}, {0, -kH, 0, -kH}});
  const float half = glm::radians(22.5f) / 2;
  expectNear4(sampleChannel(c, 0.5), {0, std::sin(half), 0, std::cos(half)});
  // Slerp, not a normalized lerp: at 45 degrees of 120 the two differ by about 0.03.
  auto wide = channel(scene::TrsPath::Rotation, scene::Interpolation::Linear, {0, 1},
                      {{0, 0, 0, 1}, {std::sin(glm::radians(60.f)), 0, 0, std::cos(glm::radians(60.f))}});
  const float quarter = glm::radians(120.0f) * 0.375f / 2;
  expectNear4(sampleChannel(wide, 0.375), {std::sin(quarter), 0, 0, std::cos(quarter)});
  // Nearly parallel keys (the spec's lerp branch) still give a unit quaternion.
  auto near = channel(scene::TrsPath::Rotation, scene::Interpolation::Linear, {0, 1},
                      {{0, 0, 0, 1}, {0.01f, 0, 0, 0.99995f}});
  EXPECT_NEAR(glm::length(sampleChannel(near, 0.5)), 1.0f, 1e-6f);
}

TEST(Animation, CubicSplineIsTheHermiteSpline) {
  // Keys (in-tangent, value, out-tangent): t=0 value 1, out-tangent 3; t=2 value 2, in-tangent
  // 0. Interval 2, so the tangents scale by 2: p(u) = h00 + 2 * 3 h10 + 2 h01.
  auto c = channel(scene::TrsPath::Scale, scene::Interpolation::CubicSpline, {0, 2},
                   {{0, 0, 0, 0}, {1, 1, 1, 0}, {3, 0, 0, 0}, {0, 0, 0, 0}, {2, 1, 1, 0}, {0, 0, 0, 0}});
  expectNear4(sampleChannel(c, 0.5), {2.0f, 1, 1, 0});   // u = 1/4: 0.84375 + 0.84375 + 0.3125
  expectNear4(sampleChannel(c, 1.0), {2.25f, 1, 1, 0});  // u = 1/2: 0.5 + 0.75 + 1
  expectNear4(sampleChannel(c, -1.0), {1, 1, 1, 0});     // the values, not the tangents
  expectNear4(sampleChannel(c, 3.0), {2, 1, 1, 0});
  // A rotation spline comes out normalized.
  auto r = channel(scene::TrsPath::Rotation, scene::Interpolation::CubicSpline, {0, 1},
                   {{0, 0, 0, 0}, {0, 0, 0, 1}, {1, 0, 0, 0}, {0, 0, 0, 0}, {kH, 0, 0, kH}, {0, 0, 0, 0}});
  EXPECT_NEAR(glm::length(sampleChannel(r, 0.5)), 1.0f, 1e-6f);
}

TEST(Animation, LoadsChannelsAndWhatTheyMove) {
  scene::Scene s = loadAnimated();
  const scene::Animation& a = s.animation;
  ASSERT_EQ(s.vertices.size(), 23u);
  EXPECT_EQ(a.channels.size(), 6u);  // the weights channel is skipped
  EXPECT_TRUE(test::hasWarning(s, "morph target weights"));
  EXPECT_FLOAT_EQ(a.startS, 0.0f);
  EXPECT_FLOAT_EQ(a.endS, 2.0f);
  EXPECT_TRUE(a.movesCameras());
  EXPECT_TRUE(a.movesGeometry());
  EXPECT_EQ(a.primitives.size(), 5u);  // all but the still quad
  // The file's rest pose until posed: the stepper at the origin, the rider at (1, 0, 0).
  expectNear(s.vertices[kStepper + 1].position, {1, 0, 0});
  expectNear(s.vertices[kRider].position, {1, 0, 0});
}

TEST(Animation, PosesNodesChildrenAndCameras) {
  scene::Scene s = loadAnimated();
  scene::PoseChange change = scene::poseScene(s, 1.0);
  EXPECT_TRUE(change.cameras && change.geometry);
  EXPECT_FALSE(change.lights);
  // STEP: the key at t = 1.
  expectNear(s.vertices[kStepper + 1].position, {2, 0, 0});
  // LINEAR: 45 degrees about +Y after the translation (0, 1, -2).
  expectNear(s.vertices[kSpinner + 1].position, {kH, 1, -2 - kH});
  expectNear(s.vertices[kSpinner + 1].normal, {kH, 0, kH});
  // The child follows its parent: (1, 0, 0) in the spinner's frame.
  expectNear(s.vertices[kRider].position, {kH, 1, -2 - kH});
  expectNear(s.vertices[kRider + 1].position, {2 * kH, 1, -2 - 2 * kH});
  // CUBICSPLINE scale 2.25 along x.
  expectNear(s.vertices[kBouncer + 2].position, {2.25f, 1, 0});
  // The camera moved halfway, rigid.
  expectNear(glm::vec3(s.cameras[0].worldFromCamera[3]), {0, 1, 7});
  // The still quad is untouched.
  expectNear(s.vertices[kStill + 1].position, {1, -3, 0});
  // Bounds follow: the stepper's far corner at x = 2.25 is the bouncer's.
  EXPECT_NEAR(s.boundsMax.x, 2.25f, 1e-5f);

  scene::poseScene(s, 2.0);
  expectNear(s.vertices[kStepper + 1].position, {4, 0, 0});
  expectNear(s.vertices[kSpinner + 1].position, {0, 2, -3});
  expectNear(glm::vec3(s.cameras[0].worldFromCamera[3]), {0, 1, 9});
}

TEST(Animation, MirroringKeepsFrontFacesAndFlatNormals) {
  scene::Scene s = loadAnimated();
  const gpu::scene::Triangle rest = s.triangles[kFlipperTriangle];
  ASSERT_EQ(rest.v0, kFlipper);
  scene::poseScene(s, 1.0);  // scale (-1, 1, 1)
  const gpu::scene::Triangle& t = s.triangles[kFlipperTriangle];
  EXPECT_EQ(t.v1, rest.v2);
  EXPECT_EQ(t.v2, rest.v1);
  expectNear(s.vertices[kFlipper + 1].position, {-1, 0, 4});
  const glm::vec3 p0 = s.vertices[t.v0].position, p1 = s.vertices[t.v1].position,
                  p2 = s.vertices[t.v2].position;
  expectNear(glm::normalize(glm::cross(p1 - p0, p2 - p0)), {0, 0, 1});
  for (uint32_t v = kFlipper; v < kFlipper + 3; ++v) expectNear(s.vertices[v].normal, {0, 0, 1});
  // Back to scale 1: the winding returns.
  scene::poseScene(s, 0.5);
  EXPECT_EQ(s.triangles[kFlipperTriangle].v1, rest.v1);
  expectNear(s.vertices[kFlipper + 1].position, {1, 0, 4});
}

TEST(Animation, CameraOnlyAnimationLeavesGeometryAlone) {
  scene::Scene s = scene::loadScene(test::dataPath("scene/camera_path.gltf"));
  ASSERT_FALSE(s.animation.empty());
  EXPECT_TRUE(s.animation.movesCameras());
  EXPECT_FALSE(s.animation.movesGeometry());
  const auto vertices = s.vertices;
  const glm::vec3 before(s.cameras[0].worldFromCamera[3]);
  scene::PoseChange change = scene::poseScene(s, 0.1);
  EXPECT_TRUE(change.cameras);
  EXPECT_FALSE(change.geometry || change.lights);
  EXPECT_GT(glm::length(glm::vec3(s.cameras[0].worldFromCamera[3]) - before), 1e-3f);
  ASSERT_EQ(s.vertices.size(), vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i)
    EXPECT_EQ(s.vertices[i].position, vertices[i].position);
}

// PoseChange::moved lists exactly the primitives whose vertices changed since the pose before,
// with their bounds at both poses (a CPU twin over the vertices); a STEP key that holds moves
// nothing, and posing at the same time again moves nothing, though the flags stay set.
TEST(Animation, PoseChangeListsWhatMovedWithItsBounds) {
  scene::Scene s = loadAnimated();
  scene::poseScene(s, 1.0);
  const auto before = s.vertices;
  const scene::PoseChange change = scene::poseScene(s, 1.5);
  EXPECT_TRUE(change.geometry);
  EXPECT_FALSE(change.lightMoved);
  size_t expected = 0;
  for (const scene::MovingPrimitive& p : s.animation.primitives) {
    glm::vec3 lo0(INFINITY), hi0(-INFINITY), lo1(INFINITY), hi1(-INFINITY);
    bool moved = false;
    for (size_t i = p.firstVertex; i < p.firstVertex + p.positions.size(); ++i) {
      moved = moved || before[i].position != s.vertices[i].position;
      lo0 = glm::min(lo0, before[i].position), hi0 = glm::max(hi0, before[i].position);
      lo1 = glm::min(lo1, s.vertices[i].position), hi1 = glm::max(hi1, s.vertices[i].position);
    }
    if (!moved) continue;
    ++expected;
    const auto same = [&](const scene::MovedPrimitive& m) {
      return m.beforeLo == lo0 && m.beforeHi == hi0 && m.afterLo == lo1 && m.afterHi == hi1;
    };
    EXPECT_TRUE(std::any_of(change.moved.begin(), change.moved.end(), same))
        << "primitive at vertex " << p.firstVertex;
  }
  EXPECT_EQ(change.moved.size(), expected);
  // From 1 to 1.5 s the STEP stepper and flipper hold their keys; the others move.
  EXPECT_EQ(expected, s.animation.primitives.size() - 2);
  for (const scene::MovedPrimitive& m : change.moved) EXPECT_FALSE(m.emissive);
  const scene::PoseChange again = scene::poseScene(s, 1.5);
  EXPECT_TRUE(again.geometry);
  EXPECT_TRUE(again.moved.empty());
}

// moving_object.gltf: the cube slides from 0 to 1 s, the point light moves from 2 to 3 s.
TEST(Animation, PoseChangeSaysWhetherALightMoved) {
  scene::Scene s = scene::loadScene(test::dataPath("scene/moving_object.gltf"));
  ASSERT_EQ(s.lights.size(), 1u);
  scene::PoseChange change = scene::poseScene(s, 0.0);  // the file's rest pose
  EXPECT_TRUE(change.lights && change.geometry);
  EXPECT_TRUE(change.moved.empty());
  EXPECT_FALSE(change.lightMoved);
  change = scene::poseScene(s, 0.5);
  ASSERT_EQ(change.moved.size(), 1u);
  expectNear(change.moved[0].beforeLo, {-1.15f, 0, 0.35f});
  expectNear(change.moved[0].afterHi, {-0.65f, 0.3f, 0.65f});
  EXPECT_FALSE(change.lightMoved);
  change = scene::poseScene(s, 2.5);
  ASSERT_EQ(change.moved.size(), 1u);  // the cube's last stretch, 0.5 to 1 s
  EXPECT_TRUE(change.lightMoved);
  expectNear(s.lights[0].position, {1, 1.8f, -0.5f});
  change = scene::poseScene(s, 4.0);
  EXPECT_TRUE(change.moved.empty());
  EXPECT_TRUE(change.lightMoved);
  EXPECT_FALSE(scene::poseScene(s, 4.0).lightMoved);
}

TEST(Animation, StaticSceneHasNoAnimation) {
  scene::Scene s = scene::loadScene(test::dataPath("scene/hierarchy.gltf"));
  EXPECT_TRUE(s.animation.empty());
  const auto vertices = s.vertices;
  scene::PoseChange change = scene::poseScene(s, 1.0);
  EXPECT_FALSE(change.cameras || change.geometry || change.lights);
  EXPECT_EQ(s.vertices[0].position, vertices[0].position);
}

TEST(Animation, BadSamplersAreRefused) {
  auto load = [](const std::string& p) { scene::loadScene(p); };
  test::expectInputError(load, test::dataPath("scene/bad_animation_times.gltf"),
                         "input times decrease at key 2");
  test::expectInputError(load, test::dataPath("scene/bad_animation_count.gltf"),
                         "output has 2 values for 2 keys, needs 6");
}
