// One Shot Radiance as an Integrator (render/integrator.h); one unit = one progressive pass:
//   gbuffer -> [cache lookup -> maps -> normalize -> U-Net -> denoise -> cache store ->
//   project, per chunk] -> direct and composite, band by band -> residual -> resolve
// all recorded in one command buffer, no host round trip. The estimator and schedule are
// documented in docs/osr.md; the grid schedule in grid_schedule.h.
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "bvh/bvh.h"
#include "nn_kernels/unet.h"
#include "osr/grid_schedule.h"
#include "osr/map_cache.h"
#include "osr/osr_buffers.h"
#include "osr/osr_passes.h"
#include "osr/osr_settings.h"
#include "render/integrator.h"
#include "scene_gpu/gpu_scene.h"

namespace osr::oneshot {

class OsrIntegrator : public render::Integrator {
 public:
  // Loads and checks the weights for Denoiser::Unet (InputError naming the file on a model
  // that does not match what this integrator feeds it).
  OsrIntegrator(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
                uint32_t width, uint32_t height, const OsrSettings& settings);
  ~OsrIntegrator() override;

  // Renders a rebuilt device scene (a shot's frame that moved meshes or lights) with this
  // integrator's pipelines, network, buffers and map cache, rather than a new integrator: none
  // of them depends on the geometry, only the bindings do, so the cache survives the rebuild
  // without being owned outside (one owner, as without animation) and the frame skips
  // building the pipelines again (about 2 s on lavapipe). What moved invalidates the cached
  // maps it may change (invalidateMoved). False, and nothing changes, when `scene` needs
  // other pass specializations (kSceneFeature* bits or texel fetch that differ: they follow
  // materials, textures, lights and the environment, which posing never changes).
  bool rebind(const scene::GpuScene& scene, const bvh::Bvh& bvh,
              const scene::PoseChange& change) override;

  const char* name() const override { return "osr"; }
  const char* unitName() const override { return "passes"; }
  uint32_t maxUnitsPerSubmission() const override { return 1; }
  // The schedule's cost model: map passes cost their maps' paths on top of the pixel work.
  double unitCost(uint32_t pass) const override;
  void restart(const scene::Camera& camera, uint32_t seed) override;
  void record(VkCommandBuffer cmd, uint32_t first, uint32_t count, vk::GpuTimer* timer) override;
  // A pass in slices for the viewer: bands of the pixel passes and small chunks of maps, in
  // the order a whole pass records them, split by the cost model.
  uint32_t maxSlicesPerUnit() const override { return 4096; }
  void recordSlice(VkCommandBuffer cmd, uint32_t unit, uint32_t slice, uint32_t slices,
                   vk::GpuTimer* timer) override;
  // A pass left unfinished is dropped: the film keeps the image of the complete passes
  // (recordSlice resolves it before a sliced pass begins). The first pass has none before it,
  // so what it recorded is resolved as the viewer shows it: the bands of direct light and
  // indirect light done so far, black where no band reached.
  void abandonUnit(uint32_t unit, uint32_t slicesDone, uint32_t slices) override;
  const render::Film& film() const override { return film_; }
  // Resolves first when record() left the film behind (resolveEverySubmission false).
  void resolveInto(render::FilmLayers& into) const override;
  // OsrSettings::residualNoiseWeight from now on; the next resolveInto resolves the passes
  // so far again with it (osr-bench compares one film's raw and denoised blends). Not after
  // abandonUnit of a later pass: the sums then hold part of it, which that resolve would show.
  void setResidualNoiseWeight(float weight);

  // Maps of the last map pass, downloaded (after the last submission): one-shot input
  // [maps][7][32][32] (only with keepAllMaps), clean [maps][3][32][32], where they were taken
  // and their projections.
  struct MapDump {
    uint32_t maps = 0, cellsX = 0, cellsY = 0, radius = 0;
    std::vector<float> oneShot, clean;
    std::vector<gpu::osr::MapPoint> points;
    std::vector<gpu::osr::MapProjection> projections;
  };
  MapDump downloadMaps() const;
  // Maps of the grids since restart() (recorded, i.e. after the submissions complete), the
  // cache's hits included.
  uint64_t mapsTraced() const { return mapsTraced_; }
  // What the map cache did at each grid point of the last map pass (after the last
  // submission): counts by MapCacheRef action (index gpu::osr::kMapCache*).
  std::array<uint32_t, 4> mapCacheActions() const;
  // The same per grid point, in MapDump::points order.
  std::vector<gpu::osr::MapCacheRef> mapCacheRefs() const;
  // The cache, when settings().mapCacheMaps > 0 (scene changes call invalidate()).
  MapCache* mapCache() { return settings_.mapCacheMaps ? cache_.get() : nullptr; }
  // The map cache after a pose change (docs/osr.md "Eviction and invalidation"). A light that
  // moved (a punctual light, or a primitive that emits) changes the light at every surface it
  // reaches, and so the maps of every point that sees one of them: all maps are stale. Any
  // other primitive that moved makes stale the maps within settings().mapCacheMovedReach
  // times its bounds' diagonal of its bounds before or after (MapCache::invalidateNear): the
  // maps that see it large, and those on it (their position moved). Past that reach it fills
  // a small part of a map's hemisphere, which stays as it was: the residual is measured
  // against whatever maps a pass uses, so a slightly stale map costs variance, not bias.
  // Returns what the cache did (both 0 without a cache); rebind() calls it.
  MapCache::Invalidated invalidateMoved(const scene::PoseChange& change);

 private:
  using Grid = gpu::osr::MapGrid;
  Grid gridOf(uint32_t radius, uint32_t mapPass) const;
  // One step of a pass: a pixel band of one pixel pass, or one chunk of maps through every map
  // pass; cost in the schedule's path units.
  struct Step {
    enum class Kind { Gbuffer, Direct, Maps, Composite, Residual } kind;
    uint32_t begin, end;  // pixels or maps
    double cost;
  };
  // The steps of pass k in recording order: each pixel pass in `bands` bands, maps in chunks
  // of at most chunkMaps (uses current_, so after beginPass(k)).
  std::vector<Step> stepsOfPass(uint32_t k, uint32_t bands, uint32_t chunkMaps) const;
  void preparePasses();        // every pipeline for bvh_'s node format, now rather than in a render
  void beginPass(uint32_t k);  // the pass's grid becomes current_
  void recordStep(VkCommandBuffer cmd, uint32_t k, const Step& step, vk::GpuTimer* timer);
  void recordResolve(VkCommandBuffer cmd, uint32_t passesDone, vk::GpuTimer* timer) const;

  const vk::Context& ctx_;
  const scene::GpuScene* scene_;  // rebind() replaces them
  const bvh::Bvh* bvh_;
  uint32_t sceneFeatures_;  // what the passes are specialised on (scene_'s when made)
  bool sceneTexelFetch_;
  uint32_t width_, height_;
  OsrSettings settings_;
  mutable GridSchedule schedule_;  // lazily extended by pass()
  render::Film film_;
  std::unique_ptr<OsrBuffers> buffers_;
  uint32_t netOutput_ = gpu::osr::kNetOutputRescaled;  // from the weights' normalization
  std::unique_ptr<nn::UNet> unet_;
  GBufferPass gbuffer_;
  DirectPass direct_;
  MapsPass maps_;
  MapNormalizePass normalize_;
  MapDenoisePass denoise_;
  MapProjectPass project_;
  MapCacheLookupPass cacheLookup_;
  MapCacheClaimPass cacheClaim_;
  MapCacheStorePass cacheStore_;
  std::unique_ptr<MapCache> cache_;  // a one-set dummy (never recorded) without the cache
  CompositePass composite_;
  ResidualPass residual_;
  ResolvePass resolve_;
  OsrBindings bindings_;
  uint32_t seed_ = 0;
  Grid current_{};  // maps in mapPoints / mapProjections / mapClean
  uint32_t currentMapPass_ = 0;  // the schedule's map pass of current_
  uint32_t cacheClock_ = 0;      // the cache's tick of current_
  uint64_t mapsTraced_ = 0;
  uint32_t passesDone_ = 0;  // by the last record() or last slice of a pass
  mutable bool filmBehind_ = false;  // record() or recordSlice() skipped the resolve
  // Pixels [0, resolvePixels_) are resolved: all of them, except after a first pass abandoned
  // part-way, whose pixel bands reached [0, reachedPixels_) (recordSlice keeps the count).
  uint32_t resolvePixels_ = 0, reachedPixels_ = 0;
};

}  // namespace osr::oneshot
