// The image denoiser switch every mode accepts (docs/denoise.md): --network default|none|FILE
// and --filter atrous|none, with each mode's default.
#pragma once
#include <string>

#include "app/args.h"
#include "render/denoiser.h"

namespace osr::app {

// Consumes --network and --filter; the mode's defaults where not given. Bad values: InputError.
render::DenoiseSettings readDenoiseOptions(Args& args, const std::string& mode);

// The --help lines of both options, with each mode's default.
std::string denoiseHelp();

}  // namespace osr::app
