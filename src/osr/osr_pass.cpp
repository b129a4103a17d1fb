#include "osr/osr_pass.h"

#include <algorithm>

#include "bvh/bvh.h"
#include "nn_kernels/tensor_view.h"
#include "osr/osr_buffers.h"
#include "render/film.h"
#include "common/error.h"

namespace osr::oneshot {

namespace o = gpu::osr;

namespace {
std::vector<vk::SpecConstant> specs(const vk::Context& ctx, uint32_t sceneFeatures,
                                    bool sceneTexelFetch, std::vector<vk::SpecConstant> extra) {
  extra.push_back(vk::specUint(o::kOsrSpecSceneFeatures, sceneFeatures));
  extra.push_back(bvh::traversalSpec(ctx));
  extra.push_back(vk::specUint(gpu::scene::kSceneSpecTexelFetch, sceneTexelFetch ? 1u : 0u));
  return extra;
}
}  // namespace

OsrPass::OsrPass(const vk::Context& ctx, shaders::Id shader, Domain domain, uint32_t sceneFeatures,
                 bool sceneTexelFetch, std::vector<vk::SpecConstant> extraSpec)
    : domain_(domain),
      pipeline_(ctx, shader, osrDescriptorTypes(), sizeof(o::OsrPush),
                specs(ctx, sceneFeatures, sceneTexelFetch, std::move(extraSpec))),
      pixelWindow_(render::windowPixels(
          ctx, std::max({sizeof(o::GBufferPixel), sizeof(o::AccumPixel), sizeof(gpu::film::FilmPixel)}))),
      mapWindow_(uint32_t(std::max<uint64_t>(1, ctx.caps().maxStorageBufferRange / kCleanMapBytes))) {}

namespace {
// The clean maps that pixels [first, first + count) read: the 3 x 3 cells around each
// (lib/osr_maps.glsl gatherMaps), as whole cell rows. Before the first map pass (or for maps
// at given pixels) no pass reads them: any valid window.
void cleanMapsOfPixels(const o::OsrPush& push, uint32_t width, uint32_t maxMaps, uint32_t mapWindow,
                       OsrWindow& w) {
  if (push.gridRadius == 0 || push.cellsX == 0 || push.cellsY == 0) {
    w.mapFirst = 0;
    w.mapCount = std::min(maxMaps, mapWindow);
    return;
  }
  const uint32_t r = push.gridRadius;
  const uint32_t y0 = w.pixelFirst / width, y1 = (w.pixelFirst + w.pixelCount - 1) / width;
  const uint32_t lo = y0 / r > 0 ? y0 / r - 1 : 0, hi = std::min(y1 / r + 1, push.cellsY - 1);
  w.mapFirst = lo * push.cellsX;
  w.mapCount = (hi - lo + 1) * push.cellsX;
}

[[noreturn]] void windowTooSmall(const char* pass, const std::string& what, uint64_t bytes,
                                 const vk::Context& ctx) {
  throw DeviceError(std::string("osr: ") + pass + ": " + what + " need " +
                    std::to_string(bytes >> 20) + " MiB in one binding, over the device's " +
                    "maxStorageBufferRange of " +
                    std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB");
}
}  // namespace

void OsrPass::record(VkCommandBuffer cmd, const OsrBindings& bindings, o::OsrPush push,
                     uint32_t pixelEnd, uint32_t pixelBegin) const {
  const vk::ComputePipeline& pipeline = pipeline_.forBvh(*bindings.bvh);
  vk::Binder binder(pipeline);
  const uint32_t width = bindings.film->width(), height = bindings.film->height();
  const uint32_t maxMaps = bindings.buffers->maxMaps;
  auto dispatch = [&](const OsrWindow& w, uint32_t x, uint32_t y) {
    bindings.fill(binder, w);
    binder.bind(cmd, push);
    pipeline.dispatch(cmd, x, y);
  };
  if (domain_ == Domain::Pixels) {
    // Windows of whole kWindowAlignPixels blocks, halved until the clean maps they read fit
    // one binding too.
    for (uint32_t first = pixelBegin; first < pixelEnd;) {
      OsrWindow w;
      w.pixelFirst = first;
      w.pixelCount = std::min({kMaxPixelsPerDispatch, pixelWindow_, pixelEnd - first});
      cleanMapsOfPixels(push, width, maxMaps, mapWindow_, w);
      while (w.mapCount > mapWindow_) {
        if (w.pixelCount <= render::kWindowAlignPixels)
          windowTooSmall(name(), "the clean maps around " + std::to_string(w.pixelCount) + " pixels",
                         w.mapCount * kCleanMapBytes, pipeline_.context());
        w.pixelCount = w.pixelCount / 2 / render::kWindowAlignPixels * render::kWindowAlignPixels;
        cleanMapsOfPixels(push, width, maxMaps, mapWindow_, w);
      }
      push.pixelOffset = w.pixelFirst;
      push.pixelCount = w.pixelCount;
      push.mapOffset = w.mapFirst;
      dispatch(w, vk::groupCount(push.pixelCount, o::kOsrWorkgroupSize), 1);
      first += w.pixelCount;
    }
  } else if (push.mapCount > 0) {
    const uint32_t chunkFirst = push.mapOffset, chunkEnd = push.mapOffset + push.mapCount;
    for (uint32_t m = chunkFirst; m < chunkEnd;) {
      OsrWindow w;
      uint32_t end = chunkEnd;
      if (domain_ == Domain::MapTexels && push.gridRadius > 0) {
        // osr_maps reads the G-buffer at each map's grid point: bind the pixel rows of the
        // chunk's cell rows, as many cell rows as one binding holds.
        const uint32_t r = push.gridRadius, rowCells = push.cellsX;
        const uint32_t a = m / rowCells;
        w.pixelFirst = a * r * width / render::kWindowAlignPixels * render::kWindowAlignPixels;
        auto pixelEnd = [&](uint32_t lastCellRow) {
          return std::min((lastCellRow + 1) * r, height) * width;
        };
        if (pixelEnd(a) - w.pixelFirst > pixelWindow_)
          windowTooSmall(name(), "the g-buffer rows of one grid cell row",
                         uint64_t(pixelEnd(a) - w.pixelFirst) * sizeof(o::GBufferPixel),
                         pipeline_.context());
        uint32_t b = a;
        while ((b + 1) * rowCells < chunkEnd && pixelEnd(b + 1) - w.pixelFirst <= pixelWindow_) ++b;
        end = std::min(chunkEnd, (b + 1) * rowCells);
        w.pixelCount = pixelEnd(b) - w.pixelFirst;
      } else {
        // Maps at given pixels read the whole G-buffer (the binder refuses what cannot be
        // bound); the map-domain passes read no pixels.
        w.pixelCount = domain_ == Domain::MapTexels ? width * height
                                                    : std::min(width * height, pixelWindow_);
      }
      w.mapFirst = m;
      w.mapCount = end - m;
      w.oneShotFirst = m - chunkFirst;
      push.mapOffset = m;
      push.mapCount = end - m;
      push.pixelOffset = w.pixelFirst;
      const uint64_t items = domain_ == Domain::MapTexels
                                 ? uint64_t(push.mapCount) * gpu::hemi::kMapTexels
                                 : uint64_t(push.mapCount);
      uint32_t x, y;
      nn::splitGroups(vk::groupCount(items, o::kOsrWorkgroupSize), x, y);
      dispatch(w, x, y);
      m = end;
    }
  }
  vk::computeBarrier(cmd);
}

}  // namespace osr::oneshot
