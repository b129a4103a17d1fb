// app's integrator registry (integrators.h), the one place the CLI, the benchmarks and the
// viewer take an integrator's name, default units and settings from: the rules it holds, on
// the options alone (no device).
#include "app/integrators.h"

#include <gtest/gtest.h>

#include "common/error.h"

using namespace osr;
using app::IntegratorSettings;

namespace {

IntegratorSettings settingsOf(std::vector<std::string> args) {
  app::Args a(std::move(args), "render");
  app::IntegratorOptions o = app::readIntegratorOptions(a);
  a.finish();
  return app::buildIntegratorSettings(o);
}

std::string errorOf(std::vector<std::string> args) {
  try {
    settingsOf(std::move(args));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Integrators, KindsAndDefaultUnits) {
  EXPECT_EQ(app::integratorNames(), (std::vector<std::string>{"path", "preview", "osr"}));
  EXPECT_EQ(app::integratorKind("path").defaultUnits, 64u);
  EXPECT_EQ(app::integratorKind("preview").defaultUnits, 4u);
  EXPECT_EQ(app::integratorKind("osr").defaultUnits, 32u);
  EXPECT_EQ(settingsOf({}).kind->name, std::string("path"));  // the default mode
  EXPECT_EQ(settingsOf({"--mode", "preview"}).unitsOrDefault(), 4u);
  EXPECT_EQ(settingsOf({"--mode", "path", "--spp", "7"}).unitsOrDefault(), 7u);
  EXPECT_EQ(settingsOf({"--mode", "osr", "--passes", "3"}).unitsOrDefault(), 3u);
  EXPECT_EQ(settingsOf({"--spp", "5"}).unitsOrDefault(), 5u);
  EXPECT_FALSE(settingsOf({"--mode", "path"}).units);
  EXPECT_EQ(errorOf({"--mode", "bogus"}), "--mode: unknown integrator 'bogus' (path, preview, osr)");
}

TEST(Integrators, WeightsImplyTheUnetUnlessADenoiserIsGiven) {
  EXPECT_EQ(settingsOf({"--mode", "osr"}).osr.denoiser, oneshot::Denoiser::Blur);
  IntegratorSettings s = settingsOf({"--mode", "osr", "--weights", "w.osrw"});
  EXPECT_EQ(s.osr.denoiser, oneshot::Denoiser::Unet);
  EXPECT_EQ(s.osr.weightsPath, "w.osrw");
  EXPECT_EQ(settingsOf({"--mode", "osr", "--weights", "w.osrw", "--denoiser", "none"}).osr.denoiser,
            oneshot::Denoiser::None);
}

TEST(Integrators, OsrBlendsItsResidualForTheImageDenoiser) {
  // docs/osr.md "Blending the residual in": half the residual's variance where a denoiser runs.
  EXPECT_EQ(settingsOf({"--mode", "osr"}).osr.residualNoiseWeight, oneshot::kDenoisedResidualNoiseWeight);
  EXPECT_EQ(settingsOf({"--mode", "osr", "--network", "none"}).osr.residualNoiseWeight,
            oneshot::kDenoisedResidualNoiseWeight);  // the a-trous filter
  EXPECT_EQ(settingsOf({"--mode", "osr", "--network", "none", "--filter", "none"}).osr.residualNoiseWeight, 1.0f);
}

TEST(Integrators, AnOptionOfAnotherModeIsRefused) {
  for (const char* option : {"--passes", "--grid-start", "--direct-spp", "--map-spp", "--map-cache",
                             "--map-cache-reach"})
    EXPECT_NE(errorOf({"--mode", "path", option, "2"}).find("are options of --mode osr"),
              std::string::npos)
        << option;
  EXPECT_NE(errorOf({"--mode", "preview", "--denoiser", "unet"}).find("options of --mode osr"),
            std::string::npos);
  EXPECT_EQ(errorOf({"--mode", "osr", "--spp", "3"}),
            "--spp: --mode osr counts progressive passes; use --passes N");
  // Without --mode the default, path tracing, is meant: OSR's options name the mode they need.
  EXPECT_NE(errorOf({"--passes", "3"}).find("are options of --mode osr"), std::string::npos);
}

TEST(Integrators, GridOptions) {
  EXPECT_EQ(settingsOf({"--mode", "osr", "--grid-start", "4"}).osr.gridMin, 4u);  // never coarser than the start
  EXPECT_EQ(settingsOf({"--mode", "osr", "--grid-start", "32", "--grid-min", "8"}).osr.gridMin, 8u);
  EXPECT_EQ(errorOf({"--mode", "osr", "--grid-start", "8", "--grid-min", "16"}),
            "--grid-min: 16 is coarser than --grid-start 8");
}

// --help's unit lines come from the registry, so every kind's default appears there.
TEST(Integrators, HelpStatesTheRegistryDefaults) {
  const std::string help = app::unitOptionsHelp();
  for (const app::IntegratorKind& k : app::integratorKinds()) {
    EXPECT_NE(help.find(k.unitOption), std::string::npos) << k.name;
    EXPECT_NE(help.find(std::to_string(k.defaultUnits)), std::string::npos) << k.name;
    EXPECT_NE(help.find(k.name), std::string::npos) << k.name;
  }
  EXPECT_EQ(help,
            "  --spp N               path, preview: samples per pixel (default 64; preview 4)\n"
            "  --passes N            osr: progressive passes (default 32)\n");
}
