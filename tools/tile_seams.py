#!/usr/bin/python3
"""The seam error of a tiled render (tools/osr_farm.py tiles RxC) against another render of the
same image: relMSE (epsilon 0.01, as osr-vk compare) of the RGB layer on the band of pixels
within --band of a tile border, and on the rest of the image. A seam shows as a band error
above the rest's; for two renders that differ only by noise the two are equal.

usage: tile_seams.py TILED.exr REF.exr RxC [--band 2] [--noise OTHER.exr]
--noise OTHER.exr: also the same figures for OTHER (an independent render of the image, another
seed) against REF, the noise floor to read the tiled figures against. One JSON line.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import exr_file  # noqa: E402
from arg_types import positive_int  # noqa: E402


def seam_mask(height: int, width: int, rows: int, cols: int, band: int) -> np.ndarray:
    """osr_farm.py's tile borders (near-equal splits), widened by band pixels each side."""
    mask = np.zeros((height, width), bool)
    for r in range(1, rows):
        y = round(r * height / rows)
        mask[max(0, y - band):y + band, :] = True
    for c in range(1, cols):
        x = round(c * width / cols)
        mask[:, max(0, x - band):x + band] = True
    return mask


def errors(test: np.ndarray, ref: np.ndarray, mask: np.ndarray) -> dict:
    e = ((test - ref) ** 2 / (ref ** 2 + 0.01)).mean(-1)
    return {"seam_relmse": float(e[mask].mean()), "rest_relmse": float(e[~mask].mean())}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="tile_seams.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("tiled")
    p.add_argument("ref")
    p.add_argument("grid", help="RxC, as given to osr_farm.py tiles")
    p.add_argument("--band", type=positive_int, default=2, help="pixels each side of a border (default 2)")
    p.add_argument("--noise", help="an independent render of the image: the noise floor")
    args = p.parse_args(argv)
    try:
        rows, cols = (int(v) for v in args.grid.split("x"))
        images = {k: exr_file.read_rgb(v) for k, v in (("tiled", args.tiled), ("ref", args.ref), ("noise", args.noise)) if v}
    except ValueError:
        print(f"tile_seams.py: '{args.grid}' is not RxC", file=sys.stderr)
        return 2
    except (OSError, exr_file.ExrError) as e:
        print(f"tile_seams.py: {e}", file=sys.stderr)
        return 2
    ref = images["ref"]
    if any(v.shape != ref.shape for v in images.values()):
        print("tile_seams.py: the images differ in size", file=sys.stderr)
        return 2
    mask = seam_mask(ref.shape[0], ref.shape[1], rows, cols, args.band)
    out = {"grid": args.grid, "band": args.band, "seam_pixels": int(mask.sum()), "tiled": errors(images["tiled"], ref, mask)}
    if "noise" in images:
        out["noise"] = errors(images["noise"], ref, mask)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
