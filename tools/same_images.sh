#!/usr/bin/env bash
# Renders path, preview, OSR (blur maps) and OSR (U-Net maps) on scenes/cornell and scenes/room
# with two osr-vk builds and fixed seeds, and compares the EXRs byte for byte: the check that a
# refactor left every image unchanged (docs/contributing.md).
# Usage: tools/same_images.sh OLD_OSR_VK NEW_OSR_VK
set -uo pipefail
if [ $# -ne 2 ] || [ "$1" = --help ] || [ "$1" = -h ]; then
  echo "usage: tools/same_images.sh OLD_OSR_VK NEW_OSR_VK" >&2
  [ $# -eq 1 ] && exit 0 || exit 2
fi
for b in "$1" "$2"; do
  [ -x "$b" ] || { echo "same_images.sh: $b: not an executable" >&2; exit 2; }
done
scenes="$(cd "$(dirname "$0")/.." && pwd)/scenes"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail=0
cases=("path --mode path --spp 4" "preview --mode preview --spp 2" "osr --mode osr --passes 3"
       "osrunet --mode osr --passes 2 --denoiser unet")
for s in cornell room; do
  for c in "${cases[@]}"; do
    read -r name args <<<"$c"
    for side in old new; do
      bin=$1; [ $side = new ] && bin=$2
      # shellcheck disable=SC2086
      "$bin" --quiet --width 96 --height 80 --offline "$out/${name}_$s.$side.exr" $args \
        "$scenes/$s/$s.gltf" || { echo "FAILED $name $s ($side build)"; fail=1; }
    done
    if cmp -s "$out/${name}_$s.old.exr" "$out/${name}_$s.new.exr"; then echo "same $name $s"
    else echo "DIFFERENT $name $s"; fail=1; fi
  done
done
exit $fail
