#include "app/args.h"
#include "app/commands.h"
#include "common/error.h"
#include "scene/scene.h"

namespace osr::app {

int runRender(const std::vector<std::string>& args) {
  Args a(args, "osr-vk");
  auto files = a.positional();
  a.finish();
  if (files.size() != 1) throw InputError("osr-vk: expected exactly one scene file");
  // TODO(#2): the preview integrator. Loading first makes bad scenes fail as they will later.
  scene::loadScene(files[0]);
  throw InputError(files[0] + ": rendering is not built yet");
}

}  // namespace osr::app
