#!/usr/bin/env bash
# From a fresh clone: install, build (Release) and render the shipped default scene to
# out.exr and out.png with the best integrator available. Extra arguments go to osr-vk.
set -euo pipefail
cd "$(dirname "$0")"
tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build
./build/osr-vk --offline out.exr --png out.png "$@" scenes/cornell/cornell.gltf
echo "osr-vk: wrote out.exr and out.png"
