#!/usr/bin/env bash
# Runs one libFuzzer target (tests/fuzz/fuzz_TARGET.cpp, docs/testing.md "Fuzzing") for
# SECONDS, configuring and building build-fuzz (clang, ASan, UBSan, -DOSR_FUZZ=ON) when needed.
#   tools/fuzz.sh --list                          the targets, one line each
#   tools/fuzz.sh TARGET SECONDS [LIBFUZZER_OPTION...]   e.g. gltf 600 -runs=1000000
# New inputs that add coverage go to build-fuzz/corpus/TARGET (kept between runs), a crash,
# leak or hang to build-fuzz/artifacts/TARGET/; the seeds are tests/fuzz/corpus/TARGET and the
# regression inputs tests/fuzz/regressions/TARGET. The last lines give the inputs run
# (stat::number_of_executed_units).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
fuzz=$root/tests/fuzz
build=${OSR_FUZZ_BUILD:-$root/build-fuzz}

usage() {
  echo "usage: tools/fuzz.sh TARGET SECONDS [libFuzzer options] | tools/fuzz.sh --list" >&2
  exit 2
}

if [ "${1:-}" = "--list" ]; then
  for f in "$fuzz"/fuzz_*.cpp; do
    name=$(basename "$f" .cpp)
    name=${name#fuzz_}
    # The first comment line after "Fuzz target: " says what it fuzzes.
    printf '%-14s %s\n' "$name" "$(sed -n '1s|^// Fuzz target: ||p' "$f")"
  done
  exit 0
fi
[ $# -ge 2 ] || usage
target=$1
seconds=$2
shift 2
[ -f "$fuzz/fuzz_$target.cpp" ] || { echo "fuzz.sh: unknown target '$target' (tools/fuzz.sh --list)" >&2; exit 2; }
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || { echo "fuzz.sh: SECONDS must be a whole number > 0, not '$seconds'" >&2; exit 2; }

if [ ! -f "$build/build.ninja" ]; then
  launcher=()
  if command -v ccache >/dev/null; then
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  fi
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DOSR_FUZZ=ON "${launcher[@]}" >/dev/null
fi
nice cmake --build "$build" --target "fuzz_$target" -j"${OSR_FUZZ_JOBS:-2}"

corpus=$build/corpus/$target
artifacts=$build/artifacts/$target
mkdir -p "$corpus" "$artifacts"
dirs=("$fuzz/corpus/$target")
[ -d "$fuzz/regressions/$target" ] && dirs+=("$fuzz/regressions/$target")
options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -close_fd_mask=3
         -print_final_stats=1 -artifact_prefix="$artifacts/")
cd "$build"
# The targets that read files write each input to a scratch folder: in memory it is several
# times faster than on disk.
if [ -z "${TMPDIR:-}" ] && [ -w /dev/shm ]; then
  export TMPDIR=/dev/shm
fi
exec nice "$build/fuzz_$target" "${options[@]}" "$@" "$corpus" "${dirs[@]}"
