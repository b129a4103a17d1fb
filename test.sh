#!/usr/bin/env bash
# From a fresh clone: install, build and run every test (Khronos validation layer on).
set -euo pipefail
cd "$(dirname "$0")"
tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build
cd build
# --repeat until-pass:2: a test that fails runs once more and fails the suite only if it fails
# again. The heap corruption cold-cache runs used to hit was the validation layer's label race,
# now worked around (docs/testing.md, "Cold shader caches"); the retry stays until cold full
# runs have passed without it.
ctest --output-on-failure -j"$(nproc)" --repeat until-pass:2 "$@"
