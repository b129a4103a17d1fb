#include <cstdio>

#include "app/args.h"
#include "app/commands.h"
#include "vk/context.h"

namespace osr::app {

int runListDevices(const std::vector<std::string>& args) {
  Args(args, "--list-devices").finish();
  for (const vk::DeviceInfo& d : vk::listDevices())
    std::printf("%u: %s (%s, Vulkan %u.%u)\n", d.index, d.name.c_str(), d.type.c_str(),
                VK_API_VERSION_MAJOR(d.apiVersion), VK_API_VERSION_MINOR(d.apiVersion));
  return 0;
}

}  // namespace osr::app
