// The interface every integrator (src/pt path tracer and preview, src/osr One Shot Radiance)
// offers the progressive driver (render/progressive_driver.h). An integrator owns its passes
// and its film; the driver owns stop rules, time budget, batching, progress and cancellation,
// so the CLI, the viewer and the Blender engine share them.
//
// Progress is counted in "units": samples per pixel for the path tracer, progressive passes
// for OSR. A submission records units [first, first + count); the driver chooses count from
// the measured seconds per unit, never above maxUnitsPerSubmission().
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>

#include "render/film.h"
#include "scene/scene.h"
#include "vk/timer.h"

namespace osr::scene {
class GpuScene;
}
namespace osr::bvh {
struct Bvh;
}

namespace osr::render {

class Integrator {
 public:
  virtual ~Integrator() = default;

  // Short name for messages and JSON ("path", "preview", "osr").
  virtual const char* name() const = 0;
  // What one unit is, for progress lines ("spp", "passes").
  virtual const char* unitName() const = 0;
  // Largest number of units one submission may hold (OSR: 1 pass; path tracer: many samples).
  virtual uint32_t maxUnitsPerSubmission() const = 0;
  // Predicted cost of unit k relative to the others (any scale): the driver plans its time
  // budget in seconds per cost, so units of unequal work (OSR's map passes) do not overrun.
  virtual double unitCost(uint32_t /*unit*/) const { return 1.0; }

  // The device scene was rebuilt after `change` (a shot's frame that moves meshes or lights):
  // renders `scene` and `bvh` from now on and returns true, keeping what stays valid of its
  // state (OSR: the map cache, less the maps near what moved); false where it cannot (the
  // default), and the caller makes a new integrator. Called between submissions, before the
  // next restart(); the scene it rendered before may be gone already.
  virtual bool rebind(const scene::GpuScene& /*scene*/, const bvh::Bvh& /*bvh*/,
                      const scene::PoseChange& /*change*/) {
    return false;
  }
  // Starts a new image of `camera` with `seed`: clears the film and every accumulated state.
  // Submits and waits (called between submissions only).
  virtual void restart(const scene::Camera& camera, uint32_t seed) = 0;
  // Records units [first, first + count) into `cmd` (one submission). Each pass opens a
  // scope on `timer` (may be null) under a stable name, for per-pass timings.
  virtual void record(VkCommandBuffer cmd, uint32_t first, uint32_t count,
                      vk::GpuTimer* timer) = 0;

  // Largest number of slices one unit may be split into, each recorded in its own submission,
  // so a front end that must redraw often (the viewer) never waits on a whole unit. 1: a unit
  // is indivisible (OSR's stages each need every pixel of the stage before).
  virtual uint32_t maxSlicesPerUnit() const { return 1; }
  // Records slice `slice` of `slices` (2 <= slices <= maxSlicesPerUnit()) of unit `unit`. The
  // driver records a unit's slices in order, one per submission, before any later unit; the
  // unit is complete after its last slice, and equals the unit recorded whole.
  virtual void recordSlice(VkCommandBuffer /*cmd*/, uint32_t /*unit*/, uint32_t /*slice*/,
                           uint32_t /*slices*/, vk::GpuTimer* /*timer*/) {}

  // The driver stopped after slice `slicesDone` - 1 of `slices` of unit `unit` and will not
  // finish it (--time or Ctrl-C in the CLI, DriverSettings::stopInUnit): what resolve() gives
  // from now on. The default keeps the film as it is, which suits an integrator whose film
  // holds per-pixel averages (the path tracer: pixels in the finished bands have one more
  // sample). Until the next restart() nothing more is recorded.
  virtual void abandonUnit(uint32_t /*unit*/, uint32_t /*slicesDone*/, uint32_t /*slices*/) {}

  // The film the passes accumulate into (the viewer displays it; resolve() downloads it).
  virtual const Film& film() const = 0;
  // Downloads the film as averaged layers (after the last submission has completed), into
  // `into` (FilmLayers::allocate), or as a new FilmLayers.
  virtual void resolveInto(FilmLayers& into) const { film().resolve(into); }
  FilmLayers resolve() const {
    FilmLayers f;
    resolveInto(f);
    return f;
  }
};

}  // namespace osr::render
