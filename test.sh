#!/usr/bin/env bash
# From a fresh clone: install, build and run every test (Khronos validation layer on).
set -euo pipefail
cd "$(dirname "$0")"
tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build
cd build
# --repeat until-pass:2: a test that fails is run once more, and fails the suite only if it
# fails again. With cold shader caches (every fresh machine, so every CI run) most full runs
# see one test hit heap corruption inside the Khronos validation layer on lavapipe
# (docs/testing.md, "The known flake"); a second attempt runs with warm caches. A test that
# fails twice still fails.
ctest --output-on-failure -j"$(nproc)" --repeat until-pass:2 "$@"
