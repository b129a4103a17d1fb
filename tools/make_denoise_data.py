#!/usr/bin/python3
"""Noisy path-traced images of generated interiors for training the image denoiser
(tools/image_unet.py, tools/train_denoiser.py).

usage: make_denoise_data.py OUT --seeds A-B [--cameras 2] [--size 128]
                            [--spp-list 1,2,4,8,16,32] [--target-spp 0] [--chunk-spp 128]
                            [--osr-vk build/osr-vk]
       make_denoise_data.py OUT --validation [--target-spp 512]
       make_denoise_data.py OUT --quick

For each seed, tools/make_interiors.py makes the scene (OUT/scenes/SEED, or --scenes DIR) and,
for each of its first --cameras cameras, `osr-vk --mode path --offline` renders it once per
entry of --spp-list, each with its own --seed, so the renders are independent. Each render is
kept as OUT/SEED_cCAM/in_SPP.npz (colour float32 3 x H x W, linear, unfiltered; albedo and
normal float16; depth float32 1 x H x W, the first hit's view-axis distance, 0 where none;
variance float32 1 x H x W, the variance of the pixel's luminance estimate: the layers osr-vk
writes in the same EXR; and light float16 1 x H x W, the share of the pixel's camera rays that
saw light directly, which the renderer's denoisers keep out of their averages). A view whose
renders were made before depth was kept gets OUT/SEED_cCAM/depth.npz instead: the depth of one
`--mode preview` render of 16 samples (the same first hits; only the pixel jitter differs, so
edges are as sharp as a 16-sample render's), rendered before anything else; likewise
OUT/SEED_cCAM/light.npz, the light share of one 16-sample path render, for renders made before
it was kept. So an older dataset gains depth in minutes:
`cp -al OLD NEW` and run this on NEW with the seeds it holds. With --target-spp N > 0 the view also gets a
reference of N samples, rendered in chunks of at most --chunk-spp (128) samples (OUT/SEED_cCAM/ref_K.npz,
each with its own seed; the reference is their spp-weighted mean).

Training needs no reference: the renders of one view are independent, so any subset of them
is a noisy input (their spp-weighted mean is a render of the summed sample count) and the
rest a noisy target with the same expectation (Noise2Noise, Lehtinen et al. 2018, with a
mean-seeking loss). 63 samples per view then give inputs of 1-48 samples, each with a target,
where a clean reference would cost 256 or more samples per view.

--validation: the held-out interiors 9001-9003 (camera 0; never in training), 256 x 256,
inputs at 1, 4, 16 and 64 samples and a reference of --target-spp samples (default 512). Run
it again with a larger --target-spp to add reference chunks. Its inputs are rendered with the
a-trous filter on, and each keeps the filter's image too (`filtered`), so that validation
measures a network against the filter on the same renders.

Resumable: a render whose .npz exists is kept, so a run stopped anywhere continues where it
was. OUT/dataset.json holds the settings and the rendering seconds per view. --quick: two
small views of seed 1 at 32 x 32 (with --validation: one of seed 9001 with a 16-spp
reference); seconds, for the tests.
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "blender" / "osr_vk"))  # exr.py: numpy only, no bpy
import exr  # noqa: E402
from arg_types import parse_seeds, positive_int  # noqa: E402
from make_interiors import make_scene  # noqa: E402

CHUNK_SPP = 128  # reference renders are split so an interrupted one loses little
VALIDATION_SEEDS = "9001-9003"
VALIDATION_SPP = [1, 4, 16, 64]


class DataError(Exception):
    """A dataset folder or render that cannot be used; the message names it."""


def parse_spp_list(text: str) -> list[int]:
    try:
        spps = [int(s) for s in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expects sample counts like 1,2,4, got '{text}'") from None
    if not spps or min(spps) < 1:
        raise argparse.ArgumentTypeError(f"sample counts must be at least 1, got '{text}'")
    return spps


GUIDE_SPP = 16  # samples of the render that gives an older view its depth or light share
# A guide older renders lack: (key in the renders, the mode of the one render that makes
# VIEW/KEY.npz for all of them). Depth needs only first hits (a preview); the share of light
# seen directly, the path tracer's camera rays.
GUIDES = (("depth", "preview"), ("light", "path"))


def read_render(path: Path) -> dict[str, np.ndarray]:
    """An osr-vk EXR as colour (float32) and albedo, normal (float16), 3 x H x W each, depth
    (float32, 1 x H x W), and where the EXR has them the variance of each pixel's luminance
    (float32, 1 x H x W) and, for a filtered render, the filtered colour (float32, 3 x H x W;
    the raw colour is then its `noisy` layer)."""
    try:
        _, _, planes = exr.read_layers(str(path))
    except exr.ExrError as e:
        raise DataError(str(e)) from None

    def stack(names: list[str], dtype) -> np.ndarray:
        missing = [n for n in names if n not in planes]
        if missing:
            raise DataError(f"{path}: no layer {missing[0]} (not an osr-vk path-mode EXR)")
        return np.stack([planes[n] for n in names]).astype(dtype)

    filtered = "noisy.R" in planes
    layers = {"colour": stack(["noisy.R", "noisy.G", "noisy.B"] if filtered else ["R", "G", "B"], np.float32),
              "albedo": stack(["albedo.R", "albedo.G", "albedo.B"], np.float16),
              "normal": stack(["normal.X", "normal.Y", "normal.Z"], np.float16),
              "depth": stack(["depth.Z"], np.float32)}
    if "variance.Y" in planes:
        layers["variance"] = stack(["variance.Y"], np.float32)
    if "light.Y" in planes:
        layers["light"] = stack(["light.Y"], np.float16)
    if filtered:
        layers["filtered"] = stack(["R", "G", "B"], np.float32)
    return layers


def lacks(render_file: Path, key: str) -> bool:
    """Whether a render was made before `key` was kept."""
    with np.load(render_file) as z:
        return key not in z.files


def render(osr_vk: str, scene_dir: Path, env: str | None, camera: int, size: int, spp: int, seed: int,
           out: Path, mode: str = "path", filtered: bool = False, keep: str | None = None) -> float:
    """One render (path-traced; `preview` for a depth guide) into out (.npz, written
    atomically); its seconds. filtered: the a-trous filter runs too and its image is kept
    beside the raw colour (validation inputs, so that networks are measured against it).
    keep: only that layer is kept (a guide for older renders)."""
    with tempfile.TemporaryDirectory(dir=out.parent) as tmp:
        image = Path(tmp) / "render.exr"
        # No learned stage; the filter only where asked (its image is then the default layer and
        # the raw estimate the "noisy" one, read_render).
        cmd = [osr_vk, "--mode", mode, "--filter", "atrous" if filtered else "none", "--network", "none",
               "--offline", str(image),
               "--exr-float", "--spp", str(spp),
               "--seed", str(seed), "--width", str(size), "--height", str(size), "--camera", str(camera),
               "--quiet", str(scene_dir / "scene.gltf")]
        if env:
            cmd[1:1] = ["--env", str(scene_dir / env)]
        start = time.monotonic()
        r = subprocess.run(cmd, stderr=subprocess.PIPE, text=True)
        seconds = time.monotonic() - start
        if r.returncode != 0:
            last = r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""
            raise DataError(f"{scene_dir} camera {camera}: osr-vk exited {r.returncode}: {last}")
        for line in r.stderr.splitlines():  # osr-vk's warnings (it ran with --quiet)
            print(f"{out.parent.name}: {line}", file=sys.stderr)
        layers = read_render(image)
        if keep:
            layers = {keep: layers[keep]}
        part = Path(tmp) / "render.npz"
        np.savez(part, spp=np.int32(spp), seed=np.int64(seed), seconds=np.float32(seconds), **layers)
        os.replace(part, out)
    return seconds


def view_jobs(seed: int, camera: int, spp_list: list[int], target_spp: int,
              chunk_spp: int = CHUNK_SPP) -> list[tuple[str, int, int]]:
    """(file name, spp, render seed) of one view: the inputs, then the reference chunks. The
    render seeds are distinct across seeds, cameras and renders."""
    base = (seed * 8 + camera) * 256
    jobs = [(f"in_{i}_{spp}.npz", spp, base + i) for i, spp in enumerate(spp_list)]
    left, k = target_spp, 0
    while left > 0:
        n = min(left, chunk_spp)
        jobs.append((f"ref_{k}_{n}.npz", n, base + 128 + k))
        left -= n
        k += 1
    return jobs


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="make_denoise_data.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", help="output folder (one subfolder per view)")
    p.add_argument("--seeds", action="append", help="interior seeds: 5, 1-20 or 1-10,40")
    p.add_argument("--cameras", type=positive_int, help="cameras per interior (default 2; validation 1)")
    p.add_argument("--size", type=positive_int, help="image width and height (default 128; validation 256)")
    p.add_argument("--spp-list", type=parse_spp_list,
                   help="sample counts of the independent noisy renders per view (default 1,2,4,8,16,32; "
                   "validation 1,4,16,64)")
    p.add_argument("--target-spp", type=int,
                   help="samples of a reference per view, 0 for none (default 0; validation 512)")
    p.add_argument("--chunk-spp", type=positive_int, default=CHUNK_SPP,
                   help=f"most samples of one reference render (default {CHUNK_SPP}; larger on a GPU, "
                   "where a process's start costs more than its samples)")
    p.add_argument("--validation", action="store_true", help=f"the held-out set: seeds {VALIDATION_SEEDS}, "
                   "camera 0, 256 x 256, with references")
    p.add_argument("--quick", action="store_true", help="two 32 x 32 views of seed 1 (tests)")
    p.add_argument("--scenes", help="where the generated interiors go (default OUT/scenes)")
    p.add_argument("--osr-vk", default=str(HERE.parent / "build" / "osr-vk"), help="the osr-vk executable")
    args = p.parse_args(argv)

    if args.quick and args.validation:
        defaults = {"seeds": ["9001"], "cameras": 1, "size": 32, "spp_list": [1, 4], "target_spp": 16}
    elif args.quick:
        defaults = {"seeds": ["1"], "cameras": 2, "size": 32, "spp_list": [1, 2, 4], "target_spp": 0}
    elif args.validation:
        defaults = {"seeds": [VALIDATION_SEEDS], "cameras": 1, "size": 256, "spp_list": VALIDATION_SPP,
                    "target_spp": 512}
    else:
        defaults = {"seeds": None, "cameras": 2, "size": 128, "spp_list": [1, 2, 4, 8, 16, 32], "target_spp": 0}
    for key, value in defaults.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    if args.seeds is None:
        p.error("--seeds is required (or --validation, --quick)")
    try:
        seeds = parse_seeds(args.seeds)
    except ValueError as e:
        p.error(f"--seeds: {e}")
    if args.size % 8:
        p.error(f"--size must be a multiple of 8 (the U-Net's), got {args.size}")
    if args.target_spp < 0:
        p.error(f"--target-spp must be 0 or more, got {args.target_spp}")
    if not os.access(args.osr_vk, os.X_OK):
        print(f"make_denoise_data.py: {args.osr_vk}: no such executable (build first or pass --osr-vk)",
              file=sys.stderr)
        return 2

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scenes = Path(args.scenes) if args.scenes else out / "scenes"
    manifest_path = out / "dataset.json"
    manifest = json.loads(manifest_path.read_text()) if manifest_path.is_file() else {}
    manifest.update({"format": "osr-vk denoise data", "size": args.size, "spp_list": args.spp_list,
                     "target_spp": max(args.target_spp, manifest.get("target_spp", 0)),
                     "validation": bool(args.validation)})
    views = manifest.setdefault("views", {})
    # Camera-major order: every interior's first view comes before any second view, so data
    # stopped early still spans all the interiors it reached. The references come after every
    # view's inputs, one chunk of each view in turn, so a stopped run leaves every view with a
    # reference of some samples rather than some views with none.
    inputs, chunks = [], []
    for cam, seed in [(cam, seed) for cam in range(args.cameras) for seed in seeds]:
        scene_dir = scenes / str(seed)
        if not (scene_dir / "scene.json").is_file():
            make_scene(seed, scene_dir, max(3, args.cameras))
        info = json.loads((scene_dir / "scene.json").read_text())
        if cam >= info["cameras"]:
            continue
        name = f"{seed}_c{cam}"
        (out / name).mkdir(exist_ok=True)
        views.setdefault(name, {"seed": seed, "camera": cam, "seconds": 0.0})
        jobs = view_jobs(seed, cam, args.spp_list, args.target_spp, args.chunk_spp)
        inputs.append([(name, scene_dir, info, cam, job) for job in jobs[:len(args.spp_list)]])
        chunks.append([(name, scene_dir, info, cam, job) for job in jobs[len(args.spp_list):]])
    groups = inputs + [[c[k] for c in chunks if k < len(c)] for k in range(max(map(len, chunks), default=0))]
    for (name, scene_dir, info, cam, _), (key, mode) in itertools.product((g[0] for g in inputs), GUIDES):
        renders = sorted((out / name).glob("in_*.npz"))
        if not renders or (out / name / f"{key}.npz").is_file() or not lacks(renders[0], key):
            continue
        try:
            seconds = render(args.osr_vk, scene_dir, info.get("env"), cam, args.size, GUIDE_SPP, 1,
                             out / name / f"{key}.npz", mode=mode, keep=key)
        except DataError as e:
            print(f"make_denoise_data.py: {e}", file=sys.stderr)
            return 2
        print(f"make_denoise_data.py: {name}: {key} of the older renders ({seconds:.1f} s)", file=sys.stderr,
              flush=True)
    start_all, done = time.monotonic(), 0
    for n, group in enumerate(groups):
        for name, scene_dir, info, cam, (file, spp, render_seed) in group:
            if (out / name / file).is_file():
                continue
            try:
                seconds = render(args.osr_vk, scene_dir, info.get("env"), cam, args.size, spp, render_seed,
                                 out / name / file, filtered=args.validation and file.startswith("in_"))
            except DataError as e:
                print(f"make_denoise_data.py: {e}", file=sys.stderr)
                return 2
            views[name]["seconds"] = round(views[name]["seconds"] + seconds, 2)
            done += spp
            tmp = manifest_path.with_suffix(".json.tmp")
            tmp.write_text(json.dumps(manifest, indent=1) + "\n")
            os.replace(tmp, manifest_path)
        elapsed = time.monotonic() - start_all
        left = elapsed / (n + 1) * (len(groups) - n - 1)
        what = group[0][0] if n < len(inputs) else f"reference chunk {n - len(inputs) + 1}"
        print(f"make_denoise_data.py: {what} done ({n + 1}/{len(groups)}), {done} spp rendered in "
              f"{elapsed / 60:.1f} min, about {left / 60:.0f} min left", file=sys.stderr, flush=True)
    tmp = manifest_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(manifest, indent=1) + "\n")
    os.replace(tmp, manifest_path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
