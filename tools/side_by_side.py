#!/usr/bin/python3
"""Images side by side in one PNG, for looking at renders against each other (docs/images).

usage: side_by_side.py OUT.png A.exr B.exr[:LAYER] ... [--exposure EV] [--gap 4] [--scale N]
                         [--crop X,Y,W,H]

Each EXR's default RGB layer (or, as FILE.exr:LAYER, its layer LAYER: `film.exr:noisy` is
osr-vk's raw colour beside its denoised one), scaled by 2^EV, clamped to [0, 1] and sRGB-encoded as
`osr-vk --png --tonemap clamp` does, left to right in the order given, with a black gap
between them. All images must have the same height. --crop shows the same rectangle of each
(pixels from the top left), to look at a detail with --scale.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "blender" / "osr_vk"))  # exr.py: numpy only, no bpy
import exr  # noqa: E402
from gltf_build import png  # noqa: E402


def srgb8(x: np.ndarray) -> np.ndarray:
    x = np.clip(np.nan_to_num(x, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0)
    s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.round(s * 255).astype(np.uint8)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="side_by_side.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out")
    p.add_argument("images", nargs="+")
    p.add_argument("--exposure", type=float, default=0.0, help="EV applied to every image (default 0)")
    p.add_argument("--gap", type=int, default=4, help="pixels between images (default 4)")
    p.add_argument("--scale", type=int, default=1,
                   help="each pixel shown as N x N, to look at small renders (default 1)")
    p.add_argument("--crop", default=None, metavar="X,Y,W,H",
                   help="show only this rectangle of each image (pixels from the top left)")
    args = p.parse_args(argv)
    crop = None
    if args.crop is not None:
        try:
            crop = [int(v) for v in args.crop.split(",")]
            if len(crop) != 4 or min(crop) < 0 or crop[2] == 0 or crop[3] == 0:
                raise ValueError
        except ValueError:
            print(f"side_by_side.py: --crop {args.crop}: expected X,Y,W,H, W and H positive",
                  file=sys.stderr)
            return 2
    panels = []
    for path in args.images:
        file, layer = path, ""
        if not Path(path).exists() and ":" in path:
            file, layer = path.rsplit(":", 1)
        try:
            _, _, planes = exr.read_layers(file)
        except (exr.ExrError, OSError) as e:
            print(f"side_by_side.py: {e}", file=sys.stderr)  # names the file and the problem
            return 2
        prefix = layer + "." if layer else ""
        if any(prefix + c not in planes for c in "RGB"):
            what = f"no RGB layer '{layer}'" if layer else "no default RGB layer"
            print(f"side_by_side.py: {file}: {what}", file=sys.stderr)
            return 2
        rgb = np.stack([planes[prefix + c] for c in "RGB"], -1).astype(np.float64)
        if crop is not None:
            x, y, w, h = crop
            if x + w > rgb.shape[1] or y + h > rgb.shape[0]:
                print(f"side_by_side.py: {path}: --crop {args.crop} reaches past its "
                      f"{rgb.shape[1]} x {rgb.shape[0]} pixels", file=sys.stderr)
                return 2
            rgb = rgb[y:y + h, x:x + w]
        scale = max(args.scale, 1)
        panels.append(srgb8(rgb * 2.0 ** args.exposure).repeat(scale, 0).repeat(scale, 1))
    height = panels[0].shape[0]
    if any(q.shape[0] != height for q in panels):
        print("side_by_side.py: the images differ in height", file=sys.stderr)
        return 2
    gap = np.zeros((height, max(args.gap, 0), 3), np.uint8)
    row = np.concatenate([x for q in panels for x in (q, gap)][:-1], 1)
    texels = [(int(r), int(g), int(b), 255) for r, g, b in row.reshape(-1, 3)]
    Path(args.out).write_bytes(png(row.shape[1], height, texels))
    return 0


if __name__ == "__main__":
    sys.exit(main())
