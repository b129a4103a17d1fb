#!/usr/bin/env bash
# Tells image denoiser weights apart on the renderer's own films (docs/training.md, "Image
# denoiser"): the same noisy films, seed 11 at the samples per pixel the bench's 5, 10 and 30 s
# reached on lavapipe (the figures of docs/denoise.md), through the a-trous filter, the shipped
# network and each WEIGHTS file, judged by tools/denoise_error.py against the two reference
# halves of denoise_default.sh (the same DATA_DIR shares them). A view's film is the same pixel
# for pixel whatever denoises it, so the ratios hold no noise of their own inputs. Appends one
# line per film and denoiser to bench/results/denoise_weights.jsonl: the error less the
# references' noise, its ratio to the shipped weights' and the filter's, and the mean
# luminance over the reference's (a loss that is not mean-seeking shows there first). The
# films are kept in DATA_DIR/films/COMMIT (the filter's and the shipped network's depend on
# the build), a weights file's under its name and hash; a tree with changes renders afresh.
#   bench/denoise_weights.sh DATA_DIR [WEIGHTS.osrw ...] [-- SCENE ...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage="usage: bench/denoise_weights.sh DATA_DIR [WEIGHTS.osrw ...] [-- SCENE ...]"
if ((!$#)) || [[ $1 == -* ]]; then
  echo "$usage" >&2
  exit 2
fi
data=$1
shift
weights=()
while (($#)) && [[ $1 != -- ]]; do
  [[ -f $1 ]] || { echo "bench/denoise_weights.sh: $1: no such weights file" >&2; exit 2; }
  # Absolute, so that a file named "filter" or "default" is not taken for those denoisers.
  weights+=("$(cd "$(dirname "$1")" && pwd)/$(basename "$1")")
  shift
done
(($#)) && shift
if (($#)); then scenes=("$@"); else scenes=(cornell room 9001 9002 9003); fi
# The sample counts the bench's 5, 10 and 30 s reached per scene (docs/denoise.md's table).
declare -A spp_lists=([cornell]="88 163 520" [room]="49 95 324" [9001]="21 44 155" [9002]="49 98 331"
  [9003]="28 56 169")
for s in "${scenes[@]}"; do
  [[ -n ${spp_lists[$s]:-} ]] || { echo "bench/denoise_weights.sh: $s: no sample counts for this scene" \
    "(one of ${!spp_lists[*]})" >&2; exit 2; }
done
# shellcheck source=bench/denoise_scenes.sh
source "$root/bench/denoise_scenes.sh"
commit=$(git -C "$root" rev-parse --short HEAD)
films=$data/films/$commit
if ! git -C "$root" diff --quiet HEAD -- . ':(exclude)bench/results'; then
  commit+=-dirty films=$data/films/$commit
  rm -rf "$films"
fi
mkdir -p "$films"
date=$(date -u +%Y-%m-%dT%H:%M:%SZ)
device=$("$root/build/osr-vk" --list-devices | sed -n '1s/^0: //p')
for s in "${scenes[@]}"; do
  denoise_scene "$data" "$s" halves
  read -ra spps <<<"${spp_lists[$s]}"
  for n in "${spps[@]}"; do
    sets=()
    for w in filter default "${weights[@]}"; do
      case $w in
        filter) label=filter net=(--network none --filter atrous) ;;
        default) label=shipped net=(--network default) ;;
        *) label=$(basename "$w" .osrw)-$(sha1sum "$w" | cut -c1-8) net=(--network "$w") ;;
      esac
      film=$films/${s}_${n}_s11_$label.exr
      [[ -f $film ]] || "$root/build/osr-vk" --mode path --spp "$n" --seed 11 --width 256 --height 256 \
        "${view[@]}" "${net[@]}" --exr-float --quiet --offline "$film" "$scene"
      sets+=("$label=$film")
    done
    /usr/bin/python3 "$root/tools/denoise_error.py" --halves "$refA" "$refB" "${sets[@]}" |
      /usr/bin/python3 -c '
import json, os, platform, sys
scene, spp, commit, date, device = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5]
lines = {l["films"]: l for l in map(json.loads, sys.stdin) if l["region"] == "image"}
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "unknown")
machine = f"{platform.node()}: {cpu}, {os.cpu_count()} cores"  # as osr-bench writes it (record.cpp)
for name, l in lines.items():
    row = {"date": date, "commit": commit, "machine": machine, "bench": "denoise_weights", "device": device, "scene": scene, "spp": spp, "seed": 11, "denoiser": name,
           "relmse": l["relmse"], "over_shipped": l["relmse"] / lines["shipped"]["relmse"],
           "over_filter": l["relmse"] / lines["filter"]["relmse"], "lum_ratio": l["lum_ratio"]}
    print(json.dumps(row))
' "$s" "$n" "$commit" "$date" "$device" | tee -a "$root/bench/results/denoise_weights.jsonl"
  done
done
