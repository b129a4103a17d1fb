#!/usr/bin/env python3
"""Writes EXR images side by side as one sRGB PNG at a common exposure (for docs/images):

    /usr/bin/python3 tools/exr_side_by_side.py ours.exr cycles.exr --out docs/images/x.png [--scale 2]
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "blender" / "osr_vk"))
import exr  # noqa: E402  (the add-on's pure-Python reader)


def rgb(path: str) -> np.ndarray:
    planes = exr.read_layers(path)[2]
    return np.stack([planes[c] for c in "RGB"], axis=-1).astype(np.float64)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("images", nargs="+")
    parser.add_argument("--out", required=True)
    parser.add_argument("--exposure", type=float, default=0.0, help="EV (0: mean of the last at 0.18)")
    parser.add_argument("--scale", type=int, default=2)
    args = parser.parse_args()
    images = [rgb(p) for p in args.images]
    gain = 2.0 ** args.exposure if args.exposure else 0.18 / max(1e-6, float(images[-1].mean()))
    tiles = []
    for im in images:
        x = np.clip(im * gain, 0.0, 1.0)
        x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
        tiles.append(np.kron((x * 255 + 0.5).astype(np.uint8), np.ones((args.scale, args.scale, 1), np.uint8)))
    gap = np.full((tiles[0].shape[0], 4, 3), 255, np.uint8)
    row = np.concatenate([t if i == 0 else np.concatenate([gap, t], axis=1) for i, t in enumerate(tiles)], axis=1)
    Image.fromarray(row).save(args.out, optimize=True)


if __name__ == "__main__":
    main()
