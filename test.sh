#!/usr/bin/env bash
# From a fresh clone: install, build and run every test (Khronos validation layer on).
set -euo pipefail
cd "$(dirname "$0")"
tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build
cd build
ctest --output-on-failure -j"$(nproc)" "$@"
