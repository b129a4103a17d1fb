// The world-space map cache (docs/osr.md "The map cache"): with a static camera it gives the
// image of no cache within the noise between two seeds; a camera that comes back to a view
// finds its maps and traces none of them on its first pass, whose image is then as close to
// the converged one as a first pass without the cache; a scene change makes every map stale;
// the cache never holds more maps than its slots; maps under the mature floor are refined.
// Across a rebuilt scene (a shot's frame that moves something; OsrIntegrator::rebind): a
// moving object makes stale the maps near it and no others, the image after the move is the
// image without a cache within noise, and a moving light makes every map stale.
#include <gtest/gtest.h>

#include <chrono>
#include <glm/gtc/matrix_transform.hpp>

#include "common/test_paths.h"
#include "image/image_metrics.h"
#include "osr/osr_test_util.h"
#include "scene/animation.h"

using namespace osr;
namespace o = gpu::osr;

namespace {

constexpr uint32_t kSize = 64;

image::RgbImage combined(const render::FilmLayers& f) {
  return {int(f.width), int(f.height), f.combined};
}

// The scene's camera turned by `degrees` about the vertical axis through its position.
scene::Camera turned(const scene::Camera& c, float degrees) {
  scene::Camera t = c;
  t.worldFromCamera = c.worldFromCamera *
                      glm::rotate(glm::mat4(1.f), glm::radians(degrees), glm::vec3(0, 1, 0));
  return t;
}

void renderPasses(oneshot::OsrIntegrator& osr, uint32_t first, uint32_t count) {
  for (uint32_t k = first; k < first + count; ++k)
    test::context().submitAndWait([&](VkCommandBuffer cmd) { osr.record(cmd, k, 1, nullptr); });
}

oneshot::OsrSettings withCache(uint32_t maps) {
  oneshot::OsrSettings s;
  s.mapCacheMaps = maps;
  s.gridStart = s.gridMin = 8;
  return s;
}

// tests/data/scene/moving_object.gltf: the cube slides 0.4 m along +X from 0 to 1 s and holds,
// the point light moves from 2 to 3 s; the camera stands still.
const std::string kMovingObject = "scene/moving_object.gltf";

// Poses `s` at `t` and builds its device scene and BVH again, as a shot's frame does
// (app::DeviceScene); returns what moved.
scene::PoseChange poseAndUpload(test::LoadedScene& s, double t) {
  const scene::PoseChange change = scene::poseScene(s.scene, t);
  s.gpu = std::make_unique<scene::GpuScene>(test::context(), s.scene);
  s.bvh = bvh::buildGpu(test::context(), s.gpu->vertices, s.gpu->triangles, s.gpu->triangleCount);
  return change;
}

// Distance from p to the box [lo, hi].
float distanceToBox(glm::vec3 p, glm::vec3 lo, glm::vec3 hi) {
  return glm::length(glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f)));
}

}  // namespace

TEST(MapCache, StaticCameraGivesTheImageOfNoCacheWithinNoise) {
  auto s = test::loadForTest(test::referencePath("room/room.gltf"));
  auto& ctx = test::context();
  const uint32_t passes = 16;
  oneshot::OsrIntegrator plain(ctx, *s.gpu, s.bvh, kSize, kSize, withCache(0));
  const auto a1 = combined(test::renderOsrPasses(plain, s, passes, 1));
  const auto a2 = combined(test::renderOsrPasses(plain, s, passes, 2));
  oneshot::OsrIntegrator cached(ctx, *s.gpu, s.bvh, kSize, kSize, withCache(4096));
  const auto c1 = combined(test::renderOsrPasses(cached, s, passes, 1));
  const double noise = image::relMse(a2, a1), diff = image::relMse(c1, a1);
  std::printf("relMSE: seed 2 against seed 1 %.5f, cache against none (seed 1) %.5f\n", noise,
              diff);
  EXPECT_LT(diff, noise);
  EXPECT_NEAR(image::meanLuminance(c1) / image::meanLuminance(a1), 1.0, 0.02);
}

TEST(MapCache, ACameraThatComesBackReusesItsMaps) {
  auto s = test::loadForTest(test::referencePath("room/room.gltf"));
  auto& ctx = test::context();
  oneshot::OsrIntegrator cached(ctx, *s.gpu, s.bvh, kSize, kSize, withCache(4096));
  const auto converged = combined(test::renderOsrPasses(cached, s, 12, 1));
  // Away and back: the first pass back traces none of the maps it had.
  cached.restart(turned(s.camera, 40.f), 1);
  renderPasses(cached, 0, 2);
  const auto away = cached.mapCacheActions();
  cached.restart(s.camera, 1);
  renderPasses(cached, 0, 1);
  const auto back = cached.mapCacheActions();
  const auto firstBack = combined(cached.resolve());
  std::printf("away: reuse %u refine %u insert %u trace %u; back: reuse %u refine %u insert %u "
              "trace %u\n",
              away[o::kMapCacheReuse], away[o::kMapCacheRefine], away[o::kMapCacheInsert],
              away[o::kMapCacheTrace], back[o::kMapCacheReuse], back[o::kMapCacheRefine],
              back[o::kMapCacheInsert], back[o::kMapCacheTrace]);
  const uint32_t maps = back[0] + back[1] + back[2] + back[3];
  EXPECT_GE(back[o::kMapCacheReuse], maps * 9 / 10);
  EXPECT_GT(away[o::kMapCacheInsert], 0u);  // the new view's own maps were traced
  // Its first image is as close to the converged one as a first pass without the cache, with
  // none of its maps traced.
  oneshot::OsrIntegrator plain(ctx, *s.gpu, s.bvh, kSize, kSize, withCache(0));
  const auto firstPlain = combined(test::renderOsrPasses(plain, s, 1, 1));
  const double eCached = image::relMse(firstBack, converged),
               ePlain = image::relMse(firstPlain, converged);
  std::printf("first pass against 12 passes: cache %.5f, none %.5f\n", eCached, ePlain);
  EXPECT_LT(eCached, 1.05 * ePlain);
}

TEST(MapCache, ASceneChangeMakesEveryMapStale) {
  auto s = test::loadForTest(test::referencePath("room/room.gltf"));
  oneshot::OsrIntegrator cached(test::context(), *s.gpu, s.bvh, kSize, kSize, withCache(4096));
  test::renderOsrPasses(cached, s, 1, 1);
  cached.mapCache()->invalidate();
  test::renderOsrPasses(cached, s, 1, 1);
  const auto actions = cached.mapCacheActions();
  EXPECT_EQ(actions[o::kMapCacheReuse] + actions[o::kMapCacheRefine], 0u);
  EXPECT_GT(actions[o::kMapCacheInsert], 0u);
}

TEST(MapCache, HoldsNoMoreMapsThanItsSlots) {
  // 16 slots for the 64 maps of a pass: at most 16 are stored, and at most 16 found again.
  auto s = test::loadForTest(test::referencePath("room/room.gltf"));
  oneshot::OsrIntegrator cached(test::context(), *s.gpu, s.bvh, kSize, kSize, withCache(16));
  ASSERT_EQ(cached.mapCache()->slots(), 16u);
  test::renderOsrPasses(cached, s, 1, 1);
  const auto first = cached.mapCacheActions();
  EXPECT_LE(first[o::kMapCacheInsert], 16u);
  EXPECT_GT(first[o::kMapCacheTrace], 0u);
  test::renderOsrPasses(cached, s, 1, 1);
  const auto again = cached.mapCacheActions();
  EXPECT_LE(again[o::kMapCacheReuse], 16u);
  EXPECT_GT(again[o::kMapCacheReuse], 0u);
}

TEST(MapCache, MapsBelowTheMaturePassesAreRefinedUntilTheyReachIt) {
  // One pass per restart (a shot's frame at a still camera): with a floor of 3 map passes, the
  // second and third restarts trace the maps again and average them in; the fourth reuses
  // them. Without a floor the second already reuses them.
  auto s = test::loadForTest(test::referencePath("room/room.gltf"));
  oneshot::OsrSettings settings = withCache(4096);
  settings.mapCacheMaturePasses = 3;
  oneshot::OsrIntegrator mature(test::context(), *s.gpu, s.bvh, kSize, kSize, settings);
  oneshot::OsrIntegrator plain(test::context(), *s.gpu, s.bvh, kSize, kSize, withCache(4096));
  for (uint32_t frame = 1; frame <= 4; ++frame) {
    test::renderOsrPasses(mature, s, 1, 1);  // one seed: the same grid points each time
    test::renderOsrPasses(plain, s, 1, 1);
    const auto m = mature.mapCacheActions(), p = plain.mapCacheActions();
    const uint32_t maps = m[0] + m[1] + m[2] + m[3];
    SCOPED_TRACE(frame);
    if (frame == 1) {
      EXPECT_GE(m[o::kMapCacheInsert], maps * 9 / 10);
      continue;
    }
    EXPECT_GE(p[o::kMapCacheReuse], maps * 9 / 10);
    if (frame < 4) {
      EXPECT_GE(m[o::kMapCacheRefine], maps * 9 / 10);
      EXPECT_EQ(m[o::kMapCacheReuse], 0u);
    } else {
      EXPECT_GE(m[o::kMapCacheReuse], maps * 9 / 10);
    }
  }
}

// The cube moves 0.4 m (0.5 to 1 s) after a still camera's frame filled the cache: on the first
// pass after the move no map within the reach of its bounds before or after is reused (it is
// traced again), and the maps well away from it are (the pass traces none of them).
TEST(MapCache, AMovingObjectMakesStaleTheMapsNearItOnly) {
  auto s = test::loadForTest(test::dataPath(kMovingObject));
  poseAndUpload(s, 0.5);
  auto& ctx = test::context();
  const oneshot::OsrSettings settings = withCache(4096);
  oneshot::OsrIntegrator cached(ctx, *s.gpu, s.bvh, kSize, kSize, settings);
  test::renderOsrPasses(cached, s, 4, 1);
  const scene::PoseChange change = poseAndUpload(s, 1.0);
  ASSERT_EQ(change.moved.size(), 1u);
  const scene::MovedPrimitive cube = change.moved[0];
  // Rebound as if nothing moved; the move's invalidation timed on its own.
  ASSERT_TRUE(cached.rebind(*s.gpu, s.bvh, scene::PoseChange{}));
  const auto t0 = std::chrono::steady_clock::now();
  const oneshot::MapCache::Invalidated inv = cached.invalidateMoved(change);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  cached.restart(s.camera, 1);  // the same grid points as before the move
  renderPasses(cached, 0, 1);
  const auto refs = cached.mapCacheRefs();
  const auto points = cached.downloadMaps().points;
  ASSERT_EQ(refs.size(), points.size());
  const float reach = settings.mapCacheMovedReach * glm::length(cube.afterHi - cube.afterLo);
  uint32_t near = 0, nearReused = 0, far = 0, farReused = 0;
  for (size_t i = 0; i < refs.size(); ++i) {
    const glm::vec3 p(points[i].position);
    const float d = std::min(distanceToBox(p, cube.beforeLo, cube.beforeHi),
                             distanceToBox(p, cube.afterLo, cube.afterHi));
    const bool reused = refs[i].action == o::kMapCacheReuse;
    if (d <= reach) {
      ++near;
      nearReused += reused;
      EXPECT_FALSE(reused) << "map " << i << " at (" << p.x << ", " << p.y << ", " << p.z << "), "
                           << d << " m from the cube, reach " << reach;
    } else if (d > reach + 1.0f) {  // past any cell that reaches in (its diagonal < 1 m here)
      ++far;
      farReused += reused;
    }
  }
  std::printf(
      "invalidateNear: %u stale, %u kept in %.2f ms; reach %.3f m; maps near the cube "
      "%u (reused %u), far %u (reused %u) of %zu\n",
      inv.stale, inv.kept, ms, reach, near, nearReused, far, farReused, refs.size());
  EXPECT_GT(inv.stale, 0u);
  EXPECT_GT(inv.kept, inv.stale);  // a small object: most maps stay
  EXPECT_GT(near, 0u);
  EXPECT_GT(far, refs.size() / 4);
  EXPECT_GE(farReused, far * 9 / 10);
}

// The frame after the move, 16 passes with the cache carried across it, against the same
// passes of a new integrator without a cache: the difference is below the noise between two
// seeds without it (a cache that kept the cube's old maps, or a rebind that kept the old BVH,
// shows the cube where it was), and the mean is the same within 2%.
TEST(MapCache, TheImageAfterAMoveIsTheImageWithoutACacheWithinNoise) {
  auto s = test::loadForTest(test::dataPath(kMovingObject));
  poseAndUpload(s, 0.5);
  auto& ctx = test::context();
  const uint32_t passes = 16;
  oneshot::OsrIntegrator cached(ctx, *s.gpu, s.bvh, kSize, kSize, withCache(4096));
  test::renderOsrPasses(cached, s, 4, 2);
  ASSERT_TRUE(cached.rebind(*s.gpu, s.bvh, poseAndUpload(s, 1.0)));
  const auto c1 = combined(test::renderOsrPasses(cached, s, passes, 1));
  oneshot::OsrIntegrator plain(ctx, *s.gpu, s.bvh, kSize, kSize, withCache(0));
  const auto a1 = combined(test::renderOsrPasses(plain, s, passes, 1));
  const auto a2 = combined(test::renderOsrPasses(plain, s, passes, 2));
  const double noise = image::relMse(a2, a1), diff = image::relMse(c1, a1);
  std::printf(
      "after the move, relMSE: seed 2 against seed 1 %.5f, cache against none (seed 1) "
      "%.5f\n",
      noise, diff);
  EXPECT_LT(diff, noise);
  EXPECT_NEAR(image::meanLuminance(c1) / image::meanLuminance(a1), 1.0, 0.02);
}

// A frame where nothing moved (1 to 1.5 s: the cube and the light hold) keeps every map; one
// where the point light moved (1.5 to 3 s) makes every map stale.
TEST(MapCache, AMovingLightMakesEveryMapStale) {
  auto s = test::loadForTest(test::dataPath(kMovingObject));
  poseAndUpload(s, 1.0);
  oneshot::OsrIntegrator cached(test::context(), *s.gpu, s.bvh, kSize, kSize, withCache(4096));
  test::renderOsrPasses(cached, s, 2, 1);
  const scene::PoseChange still = poseAndUpload(s, 1.5);
  EXPECT_TRUE(still.moved.empty() && !still.lightMoved);
  ASSERT_TRUE(cached.rebind(*s.gpu, s.bvh, still));
  test::renderOsrPasses(cached, s, 1, 1);
  const auto kept = cached.mapCacheActions();
  const uint32_t maps = kept[0] + kept[1] + kept[2] + kept[3];
  EXPECT_GE(kept[o::kMapCacheReuse], maps * 9 / 10);
  const scene::PoseChange lamp = poseAndUpload(s, 3.0);
  EXPECT_TRUE(lamp.moved.empty() && lamp.lightMoved);
  ASSERT_TRUE(cached.rebind(*s.gpu, s.bvh, lamp));
  test::renderOsrPasses(cached, s, 1, 1);
  const auto after = cached.mapCacheActions();
  std::printf("nothing moved: reuse %u of %u; the light moved: reuse %u refine %u insert %u\n",
              kept[o::kMapCacheReuse], maps, after[o::kMapCacheReuse], after[o::kMapCacheRefine],
              after[o::kMapCacheInsert]);
  EXPECT_EQ(after[o::kMapCacheReuse] + after[o::kMapCacheRefine], 0u);
  EXPECT_GT(after[o::kMapCacheInsert], 0u);
}

// How far the reach rule's kept maps are from what they should hold (the factor
// OsrSettings::mapCacheMovedReach, docs/osr.md "Eviction and invalidation"). The cache filled
// by 16 passes with the cube before its 0.4 m move is compared, map by map (the mean of its
// cosine-weighted texels: irradiance / pi), with the cache that 16 passes with the same seed
// fill after the move (what the maps should hold), and with one filled before the move with
// another seed (their own noise). The maps the rule keeps changed by less than half their
// noise on average; those it makes stale changed by more than those it keeps. By distance
// from the cube's bounds in diagonals, the change falls from 4% within 0.5 diagonals (above
// the 2-3% noise of 16-pass maps) to about 1% from 1 diagonal on.
TEST(MapCache, TheMapsKeptAfterAMoveChangeLessThanTheirNoise) {
  const uint32_t size = 128, passes = 16;
  auto& ctx = test::context();
  // The cache of each pose and seed, after `passes` passes, with the integrator that filled it.
  struct Filled {
    test::LoadedScene scene;
    std::unique_ptr<oneshot::OsrIntegrator> osr;
  };
  auto fill = [&](double t, uint32_t seed) {
    Filled f{test::loadForTest(test::dataPath(kMovingObject)), nullptr};
    poseAndUpload(f.scene, t);
    f.osr = std::make_unique<oneshot::OsrIntegrator>(ctx, *f.scene.gpu, f.scene.bvh, size, size,
                                                     withCache(4096));
    test::renderOsrPasses(*f.osr, f.scene, passes, seed);
    return f;
  };
  auto entriesOf = [](oneshot::OsrIntegrator& osr) {
    const oneshot::MapCache& c = *osr.mapCache();
    return c.entries.downloadVector<o::MapCacheEntry>(c.slots());
  };
  auto meansOf = [](oneshot::OsrIntegrator& osr) {
    const oneshot::MapCache& c = *osr.mapCache();
    const size_t texels = gpu::hemi::kMapTexels;
    const std::vector<float> clean = c.clean.downloadVector<float>(c.slots() * 3 * texels);
    std::vector<double> means(c.slots());
    for (size_t slot = 0; slot < means.size(); ++slot) {
      const float* m = clean.data() + slot * 3 * texels;
      for (size_t t = 0; t < texels; ++t)
        means[slot] +=
            (0.2126 * m[t] + 0.7152 * m[texels + t] + 0.0722 * m[2 * texels + t]) / texels;
    }
    return means;
  };
  Filled before = fill(0.0, 1), after = fill(1.0, 1), again = fill(0.0, 2);
  const auto entries = entriesOf(*before.osr), afterEntries = entriesOf(*after.osr),
             againEntries = entriesOf(*again.osr);
  const auto means = meansOf(*before.osr), afterMeans = meansOf(*after.osr),
             againMeans = meansOf(*again.osr);
  // The rule, on the cache filled before the move.
  const scene::PoseChange change = poseAndUpload(before.scene, 1.0);
  ASSERT_EQ(change.moved.size(), 1u);
  ASSERT_TRUE(before.osr->rebind(*before.scene.gpu, before.scene.bvh, change));
  const auto ruled = entriesOf(*before.osr);
  const scene::MovedPrimitive cube = change.moved[0];
  const float diag = glm::length(cube.afterHi - cube.afterLo);
  // The same map in another cache: the same cell key, first traced within a fifth of its grid
  // spacing (the same seed traces the same points; another seed's jitter moves them).
  auto find = [](const std::vector<o::MapCacheEntry>& in, const o::MapCacheEntry& e, float within) {
    for (size_t i = 0; i < in.size(); ++i)
      if (in[i].state.x == e.state.x &&
          glm::length(glm::vec3(in[i].position) - glm::vec3(e.position)) <= within * e.position.w)
        return int(i);
    return -1;
  };
  const float edges[] = {0.0f, 0.5f, 1.0f, 2.0f, 4.0f, INFINITY};
  struct Sum {
    double change = 0.0, noise = 0.0;
    int maps = 0;
    void add(double c, double n) { change += c, noise += n, ++maps; }
  } bins[5], kept, stale;
  for (size_t i = 0; i < entries.size(); ++i) {
    if (entries[i].state.x == 0) continue;
    const int j = find(afterEntries, entries[i], 0.2f), k = find(againEntries, entries[i], 1.0f);
    if (j < 0 || k < 0) continue;  // not traced in the other caches (seen before the move only)
    const double c = std::abs(means[i] - afterMeans[j]) / std::max(afterMeans[j], 1e-6);
    const double n = std::abs(means[i] - againMeans[k]) / std::max(againMeans[k], 1e-6);
    const glm::vec3 p(entries[i].position);
    const float d = std::min(distanceToBox(p, cube.beforeLo, cube.beforeHi),
                             distanceToBox(p, cube.afterLo, cube.afterHi)) /
                    diag;
    int b = 0;
    while (d >= edges[b + 1]) ++b;
    bins[b].add(c, n);
    (ruled[i].state.w == 0 ? stale : kept).add(c, n);
  }
  for (int b = 0; b < 5; ++b)
    std::printf("%.1f-%.1f diagonals from the cube: %3d maps, change %.4f, noise %.4f\n", edges[b],
                edges[b + 1], bins[b].maps, bins[b].change / std::max(bins[b].maps, 1),
                bins[b].noise / std::max(bins[b].maps, 1));
  std::printf(
      "reach %.1f diagonals: kept %d maps, change %.4f, noise %.4f; stale %d, change "
      "%.4f, noise %.4f\n",
      oneshot::kMapCacheMovedReach, kept.maps, kept.change / kept.maps, kept.noise / kept.maps,
      stale.maps, stale.change / stale.maps, stale.noise / stale.maps);
  ASSERT_GT(kept.maps, 20);
  ASSERT_GT(stale.maps, 5);
  EXPECT_LT(kept.change, 0.5 * kept.noise);
  EXPECT_GT(stale.change / stale.maps, kept.change / kept.maps);
}
