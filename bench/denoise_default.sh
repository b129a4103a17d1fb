#!/usr/bin/env bash
# The figures of docs/denoise.md "The default, against raw path tracing and OSR": the default
# (path + the shipped network)
# against raw path tracing at 5-120 s and against OSR at 5-30 s, on cornell, room and the
# held-out generated interiors 9001-9003 (made here with their path-traced references, which
# are kept: about an hour of lavapipe the first time). Appends to bench/results/denoise.jsonl.
#   bench/denoise_default.sh [DATA_DIR] [SCENE...]    (default: $TMPDIR/osr-denoise-default, all)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
data=${1:-${TMPDIR:-/tmp}/osr-denoise-default}
if (($#)); then shift; fi
if (($#)); then scenes=("$@"); else scenes=(cornell room 9001 9002 9003); fi
vk=$root/build/osr-vk bench=$root/build/osr-bench
mkdir -p "$data"
for s in "${scenes[@]}"; do
  case $s in
    cornell | room) args=(--scene "$s") ;;
    *)
      [[ -f $data/$s/scene.gltf ]] || /usr/bin/python3 "$root/tools/make_interiors.py" "$data" --seeds "$s" >/dev/null
      env=()
      [[ -f $data/$s/sky.hdr ]] && env=(--env "$data/$s/sky.hdr")
      spp=2048
      [[ $s == 9001 ]] && spp=4096
      ref=$data/ref${s}_$spp.exr
      # Two independent halves, merged: the reference then knows its own noise (ref_noise).
      if [[ ! -f $ref ]]; then
        for seed in 777 778; do
          [[ -f $data/ref${s}_$((spp / 2))_$seed.exr ]] || "$vk" --mode path --spp $((spp / 2)) --seed $seed --width 256 \
            --height 256 --camera 0 "${env[@]}" --network none --filter none --exr-float --quiet \
            --offline "$data/ref${s}_$((spp / 2))_$seed.exr" "$data/$s/scene.gltf"
        done
        /usr/bin/python3 "$root/tools/merge_references.py" "$ref" "$data/ref${s}_$((spp / 2))_777.exr:$((spp / 2))" \
          "$data/ref${s}_$((spp / 2))_778.exr:$((spp / 2))"
      fi
      args=(--scene "$data/$s/scene.gltf" --camera 0 --reference "$ref" "${env[@]}") ;;
  esac
  "$bench" denoise "${args[@]}" --rows path,path+network,osr+atrous,osr+network --budgets 5,10,30 \
    --network default --record
  "$bench" denoise "${args[@]}" --rows path,path+network --budgets 60,120 --network default --record
done
