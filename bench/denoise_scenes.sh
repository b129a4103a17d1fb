# shellcheck shell=bash disable=SC2034  # sets variables for its caller
# Sourced by the denoising benches: the five scenes they judge on and their references.
# denoise_scene DATA_DIR SCENE [halves] sets scene (the glTF), name (what osr-bench calls it),
# view (the camera and environment arguments), ref (the merged reference) and refA, refB (its
# two halves: 2 x 2048 spp of our own path tracer, seeds 777 and 778), making the interior and
# the reference on first use (about 50 minutes of lavapipe for all five). The halves are
# rendered only where the merged reference is missing or the caller passes `halves`: a kept
# reference is not made again behind its user's back. The caller sets root, the source tree.
denoise_scene() {
  local data=$1 s=$2 need=${3:-} half=2048 seed part
  : "${root:?denoise_scene: root (the source tree) is not set}"
  view=()
  case $s in
    cornell | room)
      # osr-bench knows them by name (their lines say "cornell", "room"); osr-vk by file.
      scene=$root/scenes/$s/$s.gltf name=$s ;;
    *)
      [[ -f $data/$s/scene.gltf ]] ||
        /usr/bin/python3 "$root/tools/make_interiors.py" "$data" --seeds "$s" >/dev/null
      scene=$data/$s/scene.gltf name=$data/$s/scene.gltf view=(--camera 0)
      [[ -f $data/$s/sky.hdr ]] && view+=(--env "$data/$s/sky.hdr") ;;
  esac
  ref=$data/ref${s}_$((2 * half)).exr
  refA=$data/ref${s}_${half}_777.exr refB=$data/ref${s}_${half}_778.exr
  if [[ ! -f $ref || $need == halves ]]; then
    for seed in 777 778; do
      part=$data/ref${s}_${half}_$seed.exr
      [[ -f $part ]] || "$root/build/osr-vk" --mode path --spp $half --seed $seed --width 256 --height 256 \
        "${view[@]}" --network none --filter none --exr-float --quiet --offline "$part" "$scene"
    done
  fi
  [[ -f $ref ]] || /usr/bin/python3 "$root/tools/merge_references.py" "$ref" "$refA:$half" "$refB:$half"
}
