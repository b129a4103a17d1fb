#!/usr/bin/env bash
# From a fresh clone: install, build (Release) and render the shipped default scene to
# out.exr and out.png with the best integrator available. Extra arguments go to osr-vk.
set -euo pipefail
cd "$(dirname "$0")"
tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build
# The default integrator (path tracing with the learned denoiser: the lowest error at equal time
# measured, docs/denoise.md) for 60 s. Arguments given to run.sh replace these defaults
# (e.g. ./run.sh --mode osr --time 60).
if [ $# -eq 0 ]; then set -- --time 60; fi
stamp=build/.run_started
touch "$stamp"
./build/osr-vk --offline out.exr --png out.png "$@" scenes/cornell/cornell.gltf
# Only a render writes them (./run.sh --help, say, prints the usage and writes nothing).
if [ out.exr -nt "$stamp" ] && [ out.png -nt "$stamp" ]; then
  echo "osr-vk: wrote out.exr and out.png"
fi
