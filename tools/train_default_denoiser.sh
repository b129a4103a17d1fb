#!/usr/bin/env bash
# Regenerates the shipped image denoiser (models/osr_image_denoiser.osrw) from nothing: the
# generated interiors, the noisy training renders, the validation renders with references,
# the training, the evaluation and the packed weights (docs/training.md, "Image denoiser").
# Two trainings: the kernel predictor without edge-stopping factors (osr_image_kpn_v1, run1),
# whose weights then start the shipped one with them (osr_image_kpn_v2, run; the same weights).
#
#   tools/train_default_denoiser.sh [--quick] [--work DIR] [--osr-vk PATH] [--minutes M] [--install]
#
#   --quick        the same pipeline in a minute or two (tiny renders, a few steps); its model
#                  is not for shipping
#   --work DIR     where renders and the run go (default: work/denoise in the repository)
#   --osr-vk PATH  the osr-vk executable (default: build/osr-vk)
#   --minutes M    budget of each training (default 45)
#   --install      copy the packed model to models/osr_image_denoiser.osrw and its record to
#                  models/osr_image_denoiser.json
#
# Every step resumes: renders already on disk are kept, a run with a checkpoint continues.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
py=/usr/bin/python3
quick=0 install=0 work="$root/work/denoise" osrvk="$root/build/osr-vk" minutes=45
while (($#)); do
  case "$1" in
    --quick) quick=1 ;;
    --install) install=1 ;;
    --work) work="$2"; shift ;;
    --osr-vk) osrvk="$2"; shift ;;
    --minutes) minutes="$2"; shift ;;
    -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "train_default_denoiser.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done
[ -x "$osrvk" ] || { echo "train_default_denoiser.sh: $osrvk: no osr-vk executable (build first or pass --osr-vk)" >&2; exit 2; }
((quick && install)) && { echo "train_default_denoiser.sh: --install: a --quick model is not for shipping" >&2; exit 2; }
mkdir -p "$work"
t="$root/tools"
# A run with a checkpoint continues; a finished first run (best.pt and its final checkpoint)
# is not run again once the second has started.
resume_of() { [ -f "$1/checkpoint.pt" ] && echo --resume || true; }
if ((quick)); then
  $py "$t/make_denoise_data.py" "$work/val" --validation --quick --osr-vk "$osrvk"
  $py "$t/make_denoise_data.py" "$work/data" --quick --osr-vk "$osrvk"
  train=(--quick)
else
  $py "$t/make_denoise_data.py" "$work/val" --validation --osr-vk "$osrvk"
  $py "$t/make_denoise_data.py" "$work/data" --seeds 1-28 --cameras 1 --osr-vk "$osrvk"
  train=(--k 8 --minutes "$minutes")
fi
if [ ! -f "$work/run/checkpoint.pt" ]; then
  $py "$t/train_denoiser.py" "$work/data" --val "$work/val" --out "$work/run1" --arch kpn "${train[@]}" \
    $(resume_of "$work/run1")
fi
$py "$t/train_denoiser.py" "$work/data" --val "$work/val" --out "$work/run" --arch kpn2 --init "$work/run1/best.pt" \
  --lr 1e-3 --eval-s 600 "${train[@]}" $(resume_of "$work/run")
$py "$t/weights_pack.py" "$work/run/best.pt" "$work/run/model.osrw"
if ((install)); then
  cp "$work/run/model.osrw" "$root/models/osr_image_denoiser.osrw"
  $py "$t/train_denoiser.py" --evaluate "$work/run/best.pt" --val "$work/val" --out "$work/run" \
    --record "$root/models/osr_image_denoiser.json"
  echo "train_default_denoiser.sh: installed models/osr_image_denoiser.osrw; rebuild to embed it" >&2
fi
echo "train_default_denoiser.sh: model $work/run/model.osrw, evaluation $work/run/eval.json" >&2
