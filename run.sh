#!/usr/bin/env bash
# From a fresh clone: install, build (Release) and render the shipped default scene to
# out.exr and out.png with the best integrator available. Extra arguments go to osr-vk.
set -euo pipefail
cd "$(dirname "$0")"
tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build
# Path tracing, progressive: 256 spp or 60 s, whichever ends first (on 2 lavapipe cores
# 60 s gives about 200 spp at 512 x 512). Arguments given to run.sh replace these defaults.
if [ $# -eq 0 ]; then set -- --mode path --spp 256 --time 60; fi
./build/osr-vk --offline out.exr --png out.png "$@" scenes/cornell/cornell.gltf
echo "osr-vk: wrote out.exr and out.png"
