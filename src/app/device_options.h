// The Vulkan options every osr-vk subcommand accepts: --device N|name and --validation.
#pragma once
#include "app/args.h"
#include "vk/context.h"

namespace osr::app {

// Consumes --device and --validation from `args`.
vk::ContextOptions readDeviceOptions(Args& args);

}  // namespace osr::app
