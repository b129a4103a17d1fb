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

OsrPass::OsrPass(const vk::Context& ctx, shaders::Id shader, Domain domain, size_t pushBytes,
                 uint32_t sceneFeatures, bool sceneTexelFetch,
                 std::vector<vk::SpecConstant> extraSpec)
    : domain_(domain),
      pipeline_(ctx, shader, osrDescriptorTypes(), pushBytes,
                specs(ctx, sceneFeatures, sceneTexelFetch, std::move(extraSpec))),
      pixelWindow_(render::windowPixels(
          ctx, std::max({sizeof(o::GBufferPixel), sizeof(o::AccumPixel), sizeof(gpu::film::FilmPixel)}))),
      mapWindow_(uint32_t(std::max<uint64_t>(1, ctx.caps().maxStorageBufferRange / kCleanMapBytes))) {}

namespace {
// The clean maps that pixels [first, first + count) read: the 3 x 3 cells around each
// (lib/osr_maps.glsl gatherMaps), as whole cell rows. Before the first map pass (or for maps
// at given pixels) no pass reads them: any valid window.
void cleanMapsOfPixels(const o::MapGrid& grid, uint32_t width, uint32_t maxMaps, uint32_t mapWindow,
                       OsrWindow& w) {
  if (grid.radius == 0 || grid.cellsX == 0 || grid.cellsY == 0) {
    w.mapFirst = 0;
    w.mapCount = std::min(maxMaps, mapWindow);
    return;
  }
  const uint32_t r = grid.radius;
  const uint32_t y0 = w.pixelFirst / width, y1 = (w.pixelFirst + w.pixelCount - 1) / width;
  const uint32_t lo = y0 / r > 0 ? y0 / r - 1 : 0, hi = std::min(y1 / r + 1, grid.cellsY - 1);
  w.mapFirst = lo * grid.cellsX;
  w.mapCount = (hi - lo + 1) * grid.cellsX;
}

[[noreturn]] void windowTooSmall(const char* pass, const std::string& what, uint64_t bytes,
                                 const vk::Context& ctx) {
  throw DeviceError(std::string("osr: ") + pass + ": " + what + " need " +
                    std::to_string(bytes >> 20) + " MiB in one binding, over the device's " +
                    "maxStorageBufferRange of " +
                    std::to_string(ctx.caps().maxStorageBufferRange >> 20) + " MiB");
}
}  // namespace

std::vector<OsrWindow> OsrPass::pixelWindows(const OsrBindings& bindings, const o::MapGrid& grid,
                                             uint32_t begin, uint32_t end) const {
  const uint32_t width = bindings.film->width();
  const uint32_t maxMaps = bindings.buffers->maxMaps;
  std::vector<OsrWindow> windows;
  // Windows of whole kWindowAlignPixels blocks, halved until the clean maps they read fit
  // one binding too.
  for (uint32_t first = begin; first < end;) {
    OsrWindow w;
    w.pixelFirst = first;
    w.pixelCount = std::min({kMaxPixelsPerDispatch, pixelWindow_, end - first});
    cleanMapsOfPixels(grid, width, maxMaps, mapWindow_, w);
    while (w.mapCount > mapWindow_) {
      if (w.pixelCount <= render::kWindowAlignPixels)
        windowTooSmall(name(), "the clean maps around " + std::to_string(w.pixelCount) + " pixels",
                       w.mapCount * kCleanMapBytes, pipeline_.context());
      w.pixelCount = w.pixelCount / 2 / render::kWindowAlignPixels * render::kWindowAlignPixels;
      cleanMapsOfPixels(grid, width, maxMaps, mapWindow_, w);
    }
    windows.push_back(w);
    first += w.pixelCount;
  }
  return windows;
}

std::vector<OsrWindow> OsrPass::mapWindows(const OsrBindings& bindings, const o::MapGrid& grid,
                                           uint32_t first, uint32_t count) const {
  const uint32_t width = bindings.film->width(), height = bindings.film->height();
  std::vector<OsrWindow> windows;
  const uint32_t chunkEnd = first + count;
  for (uint32_t m = first; m < chunkEnd;) {
    OsrWindow w;
    uint32_t end = chunkEnd;
    if (domain_ == Domain::MapTexels && grid.radius > 0) {
      // osr_maps reads the G-buffer at each map's grid point: bind the pixel rows of the
      // chunk's cell rows, as many cell rows as one binding holds.
      const uint32_t r = grid.radius, rowCells = grid.cellsX;
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
    w.oneShotFirst = m - first;
    windows.push_back(w);
    m = end;
  }
  return windows;
}

glm::uvec2 OsrPass::groupsOf(const OsrWindow& w) const {
  if (domain_ == Domain::Pixels) return {vk::groupCount(w.pixelCount, o::kOsrWorkgroupSize), 1u};
  const uint64_t perMap = domain_ == Domain::MapTexels   ? gpu::hemi::kMapTexels
                          : domain_ == Domain::MapGroups ? o::kOsrWorkgroupSize
                                                         : 1;
  const uint64_t items = uint64_t(w.mapCount) * perMap;
  uint32_t x, y;
  nn::splitGroups(vk::groupCount(items, o::kOsrWorkgroupSize), x, y);
  return {x, y};
}

}  // namespace osr::oneshot
