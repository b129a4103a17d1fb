#!/usr/bin/env bash
# The figures of docs/denoise.md "The default, against raw path tracing and OSR": raw path
# tracing, path + the a-trous filter and the default (path + the shipped network) at 5-30 s,
# raw path and the default at 60 and 120 s, on cornell, room and the held-out generated
# interiors 9001-9003. The references are our own path tracer's, two independent halves
# merged, so that each line carries the reference's own noise (ref_noise): 2 x 2048 spp each
# (made here and kept: about 50 minutes of lavapipe the first time). With halves of 512
# samples the fireflies of 9003's lamps ranked the denoisers the wrong way round, and 1024
# still moved its figures (docs/denoise.md "References"). Appends to bench/results/denoise.jsonl.
#   bench/denoise_default.sh [DATA_DIR] [SCENE...]    (default: $TMPDIR/osr-denoise-default, all)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
data=${1:-${TMPDIR:-/tmp}/osr-denoise-default}
if (($#)); then shift; fi
if (($#)); then scenes=("$@"); else scenes=(cornell room 9001 9002 9003); fi
bench=$root/build/osr-bench
mkdir -p "$data"
source "$root/bench/denoise_scenes.sh"
for s in "${scenes[@]}"; do
  denoise_scene "$data" "$s"
  args=(--scene "$name" --reference "$ref" "${view[@]}" --network default --record)
  "$bench" denoise "${args[@]}" --rows path,path+atrous,path+network --budgets 5,10,30
  "$bench" denoise "${args[@]}" --rows path,path+network --budgets 60,120
done
