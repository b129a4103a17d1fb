// The world-space map cache (docs/osr.md "The map cache"): with a static camera it gives the
// image of no cache within the noise between two seeds; a camera that comes back to a view
// finds its maps and traces none of them on its first pass, whose image is then as close to
// the converged one as a first pass without the cache; a scene change makes every map stale;
// the cache never holds more maps than its slots; maps under the mature floor are refined.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "image/image_metrics.h"
#include "osr/osr_test_util.h"

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
