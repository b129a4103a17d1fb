// The osr-vk subcommands. Each takes the arguments after its name and returns the exit code;
// errors are thrown as InputError (exit 2) or other exceptions (exit 1) and printed by main.
#pragma once
#include <string>
#include <vector>

namespace osr::app {

// osr-vk [options] scene.gltf: render (viewer, or --offline out.exr).
int runRender(const std::vector<std::string>& args);
// osr-vk --list-devices
int runListDevices(const std::vector<std::string>& args);
// osr-vk unet --weights FILE --in maps.f32 --out pred.f32
int runUnet(const std::vector<std::string>& args);
// osr-vk compare a.exr b.exr
int runCompare(const std::vector<std::string>& args);

}  // namespace osr::app
