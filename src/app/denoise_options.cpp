#include "app/denoise_options.h"

#include "common/error.h"

namespace osr::app {

namespace {

// Each mode's default, the lowest relMSE at equal time measured (docs/denoise.md, "The
// default, against raw path tracing and OSR"): for path tracing and OSR the shipped network
// (osr_image_kpn_v4), which beats the a-trous filter on five scenes at 5-30 s on path tracing
// and in 11 of 13 scenes and budgets on OSR, with the filter below 4 samples per pixel (OSR:
// passes), where the network is worse (a build without the model: the filter); nothing for the
// preview.
render::DenoiseSettings modeDefault(const std::string& mode) {
  render::DenoiseSettings s;
  s.atrous = mode == "path" || mode == "osr";
  if (s.atrous && render::defaultImageModel()) s.network = render::DenoiseSettings::Network::Default;
  return s;
}

}  // namespace

std::string denoiseHelp() {
  auto defaults = [](bool network) {
    std::string out;
    for (const char* mode : {"path", "osr", "preview"}) {
      const render::DenoiseSettings d = modeDefault(mode);
      const char* value = network ? (d.network == render::DenoiseSettings::Network::Default ? "default" : "none")
                                  : (d.atrous ? "atrous" : "none");
      out += std::string(out.empty() ? "" : ", ") + mode + " " + value;
    }
    return out;
  };
  return "  --network default|none|FILE  learned image denoiser (docs/denoise.md) on the final\n"
         "                        image, and in the viewer every few units: default = the\n"
         "                        shipped model, FILE = a packed image denoiser\n"
         "                        (default per mode: " + defaults(true) + ")\n"
         "  --filter atrous|none  edge-aware a-trous filter (SVGF) where no network runs,\n"
         "                        and instead of it below 4 samples per pixel; a --crop\n"
         "                        tile is not filtered unless asked (its edges would not\n"
         "                        match its neighbours')\n"
         "                        (default per mode: " + defaults(false) + ")\n"
         "                        From 64 samples per pixel, either one's image gains the\n"
         "                        film's mean gap from it over neighbours of the same\n"
         "                        surface and returns to the raw film where they still\n"
         "                        differ by more than its noise, so the denoised image\n"
         "                        converges as samples grow\n";
}

render::DenoiseSettings readDenoiseOptions(Args& args, const std::string& mode) {
  render::DenoiseSettings s = modeDefault(mode);
  if (auto network = args.value("--network")) {
    s.chosen = true;
    if (*network == "none") {
      s.network = render::DenoiseSettings::Network::None;
    } else if (*network == "default") {
      s.network = render::DenoiseSettings::Network::Default;
    } else if (network->empty()) {
      throw InputError("--network: expected default, none or a packed image denoiser file");
    } else {
      s.network = render::DenoiseSettings::Network::File;
      s.networkFile = *network;
    }
  }
  if (auto filter = args.value("--filter")) {
    s.chosen = true;
    if (*filter != "atrous" && *filter != "none")
      throw InputError("--filter: unknown filter '" + *filter + "' (atrous, none)");
    s.atrous = *filter == "atrous";
  }
  return s;
}

}  // namespace osr::app
