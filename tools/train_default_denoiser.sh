#!/usr/bin/env bash
# Regenerates the shipped image denoiser (models/osr_image_denoiser.osrw) from nothing: the
# generated interiors, the noisy training renders, the validation renders with references,
# the training, the evaluation and the packed weights (docs/training.md, "Image denoiser").
# Four trainings, each started from the last one's weights (the kernel architectures share
# them): the kernel predictor without fixed factors (osr_image_kpn_v1, run1), with the normal
# and depth factors (osr_image_kpn_v2, run2), with the a-trous filter's factors too
# (osr_image_kpn_v3, run3), which reads the renders' variance, the one shipped before (run):
# osr_image_kpn_v4 (v3 whose pixels on edges compare mean normals) trained on at the sample
# counts a render of seconds reaches (16-400, --min-spp 16) on more interiors, two cameras
# each, with a 256-sample render besides (data2), then the shipped one (run_high): the same
# architecture trained on at 16-1600 samples per pixel, what renders of 5-120 s reach, on
# renders of up to 1024 samples (data3).
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
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "train_default_denoiser.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done
[ -x "$osrvk" ] || { echo "train_default_denoiser.sh: $osrvk: no osr-vk executable (build first or pass --osr-vk)" >&2; exit 2; }
((quick && install)) && { echo "train_default_denoiser.sh: --install: a --quick model is not for shipping" >&2; exit 2; }
mkdir -p "$work"
t="$root/tools"
# Earlier pipelines trained v3 into run/ (the three-stage one without a run3/): going on from
# there would resume that run as the v4 one and pack it as if it were.
if [ -f "$work/run/checkpoint.pt" ] && { [ ! -d "$work/run3" ] || ! $py -c "import sys, torch; \
    sys.exit(torch.load(sys.argv[1], map_location='cpu').get('architecture') != 'osr_image_kpn_v4')" \
    "$work/run/checkpoint.pt" 2>/dev/null; }; then
  echo "train_default_denoiser.sh: $work/run holds a run of an earlier pipeline: use a fresh --work" >&2
  exit 2
fi
# A run with a checkpoint continues; a finished run (best.pt and its final checkpoint) is not
# run again once a later one has started.
resume_of() { [ -f "$1/checkpoint.pt" ] && echo --resume || true; }
if ((quick)); then
  $py "$t/make_denoise_data.py" "$work/val" --validation --quick --osr-vk "$osrvk"
  $py "$t/make_denoise_data.py" "$work/data" --quick --osr-vk "$osrvk"
  train=(--quick)
else
  $py "$t/make_denoise_data.py" "$work/val" --validation --spp-list 1,4,16,64,256 --target-spp 4096 \
    --chunk-spp 512 --osr-vk "$osrvk"
  $py "$t/make_denoise_data.py" "$work/data" --seeds 1-28 --cameras 1 --spp-list 1,2,4,8,16,32,64,128 \
    --osr-vk "$osrvk"
  $py "$t/make_denoise_data.py" "$work/data2" --seeds 1-40 --cameras 2 --spp-list 1,2,4,8,16,32,64,128,256 \
    --osr-vk "$osrvk"
  $py "$t/make_denoise_data.py" "$work/data3" --seeds 1-20 --cameras 1 \
    --spp-list 4,8,16,32,64,128,256,512,1024 --osr-vk "$osrvk"
  train=(--k 8 --minutes "$minutes")
fi
if [ ! -f "$work/run2/checkpoint.pt" ] && [ ! -f "$work/run3/checkpoint.pt" ] && [ ! -f "$work/run/checkpoint.pt" ]; then
  $py "$t/train_denoiser.py" "$work/data" --val "$work/val" --out "$work/run1" --arch kpn "${train[@]}" \
    $(resume_of "$work/run1")
fi
if [ ! -f "$work/run3/checkpoint.pt" ] && [ ! -f "$work/run/checkpoint.pt" ]; then
  $py "$t/train_denoiser.py" "$work/data" --val "$work/val" --out "$work/run2" --arch kpn2 --init "$work/run1/best.pt" \
    --lr 1e-3 --eval-s 600 "${train[@]}" $(resume_of "$work/run2")
fi
if [ ! -f "$work/run/checkpoint.pt" ]; then
  $py "$t/train_denoiser.py" "$work/data" --val "$work/val" --out "$work/run3" --arch kpn3 --init "$work/run2/best.pt" \
    --lr 1e-3 --eval-s 300 "${train[@]}" $(resume_of "$work/run3")
fi
data2="$work/data2"
((quick)) && data2="$work/data"
data3="$work/data3"
((quick)) && data3="$work/data"
if [ ! -f "$work/run_high/checkpoint.pt" ]; then
  $py "$t/train_denoiser.py" "$data2" --val "$work/val" --out "$work/run" --arch kpn4 --init "$work/run3/best.pt" \
    --lr 3e-4 --min-spp "$((quick ? 1 : 16))" --eval-s 600 "${train[@]}" $(resume_of "$work/run")
fi
$py "$t/train_denoiser.py" "$data3" --val "$work/val" --out "$work/run_high" --arch kpn4 --init "$work/run/best.pt" \
  --lr 3e-4 --min-spp "$((quick ? 1 : 16))" --eval-s 900 "${train[@]}" $(resume_of "$work/run_high")
final="$work/run_high"
# The shipped weights are the run's last moving average, not its best.pt: the validation's
# three views told them apart by 1.4 %, and best.pt (halfway) kept more fireflies on dark
# faces (docs/training.md, "Image denoiser"). train_denoiser.py writes it as final.pt.
$py "$t/weights_pack.py" "$final/final.pt" "$final/model.osrw"
if ((install)); then
  cp "$final/model.osrw" "$root/models/osr_image_denoiser.osrw"
  $py "$t/train_denoiser.py" --evaluate "$final/final.pt" --val "$work/val" --out "$final" \
    --record "$root/models/osr_image_denoiser.json"
  echo "train_default_denoiser.sh: installed models/osr_image_denoiser.osrw; rebuild to embed it" >&2
fi
echo "train_default_denoiser.sh: model $final/model.osrw, evaluation $final/eval.json" >&2
