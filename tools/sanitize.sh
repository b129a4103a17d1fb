#!/usr/bin/env bash
# Builds build-asan with AddressSanitizer and UndefinedBehaviorSanitizer (-DOSR_SANITIZE) and
# runs the fast suites in it, with the validation layer on and cold shader caches (an empty
# XDG_CACHE_HOME, removed afterwards). What CI runs (.ci/run); docs/testing.md, "Sanitizers".
#   tools/sanitize.sh            the fast suites: loaders, image I/O, packed weights, the Vulkan
#                                core, osr-vk's and osr-bench's command-line checks, and the
#                                OpenEXR fuzz targets' seeds and regression inputs
#   tools/sanitize.sh --all      every suite (builds everything; many times slower: the path
#                                tracer's and OSR's integrator suites take 10 minutes and more,
#                                app/test_cmd_render 5, under ASan with cold caches on 2 loaded
#                                cores: docs/testing.md, "Sanitizers")
# Further arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
fast=(scene/test_loader scene/test_environment image/test_image_io nn_kernels/test_weights
      vk/test_context vk/test_exception_safety vk/test_shared_layout vk/test_spirv_info
      app/test_cli_errors fuzz/exr fuzz/env)
all=0
if [[ ${1:-} == --all ]]; then all=1; shift; fi

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DOSR_SANITIZE=address,undefined >/dev/null
if ((all)); then
  cmake --build build-asan
  select=()
else
  targets=(osr-vk osr-bench)  # the app/ tests run the built osr-vk and osr-bench
  # A fuzz target's CTest replay (fuzz/NAME) is the executable fuzz_NAME_replay.
  for t in "${fast[@]}"; do
    target=${t/\//_}
    [[ $t == fuzz/* ]] && target+=_replay
    targets+=("$target")
  done
  cmake --build build-asan --target "${targets[@]}"
  regex=$(IFS='|'; echo "^(${fast[*]})\$")
  select=(-R "$regex")
fi

cache=$(mktemp -d)
trap 'rm -rf "$cache"' EXIT
cd build-asan
# Leak suppressions are for third-party code only, each with its reason (the file says why).
XDG_CACHE_HOME=$cache \
LSAN_OPTIONS=suppressions=$PWD/../tests/sanitizers/lsan.supp \
UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure -j"$(nproc)" "${select[@]}" "$@"
