#!/usr/bin/python3
"""Writes a training set of hemisphere maps: procedural interiors (make_interiors.py) traced
by `osr-vk maps`, the OSR integrator's own map pass (docs/maps_format.md).

usage: make_dataset.py OUT --seeds 1-40 [--cameras 1] [--grid 16] [--size 256] [--views 1]
                       [--reference-spp 16] [--osr-vk build/osr-vk] [--scenes DIR]

For each seed it generates the scene (OUT/scenes/SEED, kept so that a shard can be traced
again) and, for each of the scene's first `--cameras` cameras, runs
`osr-vk maps --camera C --grid G --views V --reference-spp N --seed SEED*16+C`, which writes
the shard OUT/SEED_cC/ (input.npy, target.npy, points.npy, index.json). With
`--reference-spp 1` the target is an independent one-path map of the same points: a
Noise2Noise target (Lehtinen et al. 2018).

Resumable: a shard whose index.json exists with the same settings is kept. OUT/dataset.json
lists every shard (path, count, seed, camera, seconds) with the totals and the throughput in
examples per second, rewritten after each shard, so an interrupted run loses one shard.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from arg_types import parse_seeds, positive_int  # noqa: E402
from make_interiors import make_scene  # noqa: E402


def shard_settings(args) -> dict:
    return {"grid": args.grid, "width": args.size, "height": args.size, "views": args.views,
            "reference_spp": args.reference_spp}


def shard_done(shard: Path, settings: dict) -> dict | None:
    try:
        index = json.loads((shard / "index.json").read_text())
    except (OSError, ValueError):
        return None
    return index if all(index.get(k) == v for k, v in settings.items()) else None


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="make_dataset.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", help="dataset folder")
    p.add_argument("--seeds", action="append", required=True, help="scene seeds: 1-40 or 1,5,9")
    p.add_argument("--cameras", type=positive_int, default=1, help="cameras traced per scene (default 1)")
    p.add_argument("--grid", type=positive_int, default=16, help="one map per GRID x GRID pixel cell (default 16)")
    p.add_argument("--size", type=positive_int, default=256, help="image width and height (default 256)")
    p.add_argument("--views", type=positive_int, default=1, help="jittered views per camera (default 1)")
    p.add_argument("--reference-spp", type=positive_int, default=16,
                   help="paths per texel of the target; 1 = Noise2Noise target (default 16)")
    p.add_argument("--osr-vk", default=str(HERE.parent / "build" / "osr-vk"), help="the osr-vk executable")
    p.add_argument("--scenes", help="where generated scenes go (default OUT/scenes)")
    args = p.parse_args(argv)
    out = Path(args.out)
    scenes = Path(args.scenes) if args.scenes else out / "scenes"
    try:
        seeds = parse_seeds(args.seeds)
    except ValueError as e:
        print(f"make_dataset.py: --seeds: {e}", file=sys.stderr)
        return 2
    if not Path(args.osr_vk).is_file():
        print(f"make_dataset.py: {args.osr_vk}: no such executable (build first or pass --osr-vk)", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    settings = shard_settings(args)
    manifest_path = out / "dataset.json"
    try:
        manifest = json.loads(manifest_path.read_text())
    except (OSError, ValueError):
        manifest = {"format": "osr-vk dataset", "settings": settings, "shards": []}
    shards = {s["path"]: s for s in manifest["shards"]}
    for seed in seeds:
        scene_dir = scenes / str(seed)
        if not (scene_dir / "scene.json").is_file():
            make_scene(seed, scene_dir, max(3, args.cameras))
        info = json.loads((scene_dir / "scene.json").read_text())
        for cam in range(min(args.cameras, info["cameras"])):
            name = f"{seed}_c{cam}"
            shard = out / name
            index = shard_done(shard, settings)
            seconds = shards.get(name, {}).get("seconds", 0.0)
            if index is None:
                cmd = [args.osr_vk, "maps", str(scene_dir / "scene.gltf"), "--out", str(shard),
                       "--grid", str(args.grid), "--width", str(args.size), "--height", str(args.size),
                       "--camera", str(cam), "--views", str(args.views), "--seed", str(seed * 16 + cam),
                       "--reference-spp", str(args.reference_spp), "--quiet"]
                if info.get("env"):
                    cmd += ["--env", str(scene_dir / info["env"])]
                t0 = time.monotonic()
                r = subprocess.run(cmd, stderr=subprocess.PIPE, text=True)
                seconds = time.monotonic() - t0
                if r.returncode != 0:
                    print(f"make_dataset.py: seed {seed} camera {cam}: osr-vk maps failed: "
                          f"{r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode}",
                          file=sys.stderr)
                    return 1
                for line in r.stderr.splitlines():  # osr-vk's warnings (it ran with --quiet)
                    print(f"{name}: {line}", file=sys.stderr)
                index = shard_done(shard, settings)
            shards[name] = {"path": name, "count": index["count"], "seed": seed, "camera": cam,
                            "lighting": info.get("lighting"), "seconds": round(seconds, 2)}
            total = sum(s["count"] for s in shards.values())
            secs = sum(s["seconds"] for s in shards.values())
            manifest.update(settings=settings, shards=list(shards.values()), examples=total,
                            seconds=round(secs, 1), examples_per_second=round(total / max(secs, 1e-9), 2))
            tmp = manifest_path.with_suffix(".json.tmp")
            tmp.write_text(json.dumps(manifest, indent=1) + "\n")
            tmp.replace(manifest_path)
            print(f"{name}: {index['count']} maps in {seconds:.1f} s; total {total} maps, "
                  f"{manifest['examples_per_second']} maps/s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
