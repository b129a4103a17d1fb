#include "app/device_options.h"

namespace osr::app {

vk::ContextOptions readDeviceOptions(Args& args) {
  vk::ContextOptions options;
  options.device = args.value("--device").value_or("");
  options.validation = args.flag("--validation");
  return options;
}

}  // namespace osr::app
