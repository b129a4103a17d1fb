#!/usr/bin/python3
"""Where a denoised image's error is, and whether it is bias or noise.

usage: denoise_error.py --halves A.exr B.exr NAME=FILM.exr[,FILM.exr...] [NAME=...]
                        [--region NAME=X,Y,W,H ...] [--gate N]

A and B are two independent reference renders of one view (`osr-vk --mode path --network none
--filter none --exr-float` at two seeds, as merged by merge_references.py). Each NAME= lists the
same view's films through one denoiser at independent seeds (FILM.exr:LAYER reads a layer:
`film.exr:noisy` is the raw colour). Per film set and region (the whole image first), one JSON
line:

- relmse: the error less the references' noise, the mean over seeds and pixels of
  (x - a)(x - b) / (m^2 + 0.01), m = (a + b) / 2: nearly unbiased for the relMSE against the
  truth, since a and b are independent of x and of each other (nearly: the weight depends on
  them through m);
- variance and bias2 (two seeds or more): relmse split into the films' spread over seeds and
  the rest, (mu - a)(mu - b) / (m^2 + 0.01) less variance / seeds, mu the seeds' mean;
- top1_share: the share of the region's error in its worst 1 % of pixels (of the pixels'
  errors clamped at 0: less the noise, a pixel's can be negative);
- lum_ratio: the films' mean luminance over the references' (a denoiser that darkens or
  brightens shows there).

A region's figures are its sums over the whole image's pixel count, so that regions add up to
the image's. --gate N: for the first two sets, per seed and N x N block, the set whose error
against A is lower, judged against B alone (less B's noise, (a - b)^2 / 2: halves of equal
samples): an estimate of what a per-block choice between them made with a reference's help
achieves, which a learned choice, without one, would hardly beat.

Bad input (a missing or unreadable file, images of other sizes, a region outside the image, a
set whose seeds differ in number from the other's under --gate) is one line on stderr, exit 2
(a malformed option is argparse's usage and message, exit 2).
"""
from __future__ import annotations

import argparse
import json
import struct
import sys
import zlib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import exr_file  # noqa: E402


class InputError(Exception):
    pass


def read_rgb(arg: str) -> np.ndarray:
    """3 x H x W float64 of FILE.exr's colour, or of FILE.exr:LAYER's layer."""
    path, sep, layer = arg.rpartition(":")
    if not sep or not path.endswith(".exr"):
        path, layer = arg, ""
    try:
        return exr_file.read_rgb(path, layer).transpose(2, 0, 1).astype(np.float64)
    except exr_file.ExrError as e:
        raise InputError(str(e) if path in str(e) else f"{path}: {e}") from None
    except (OSError, zlib.error, ValueError, struct.error, IndexError, KeyError) as e:
        raise InputError(f"{path}: cannot read ({e})") from None


def region_box(arg: str, shape: tuple[int, int]) -> tuple[str, tuple[slice, slice]]:
    name, sep, box = arg.partition("=")
    try:
        x, y, w, h = (int(v) for v in box.split(","))
    except ValueError:
        raise InputError(f"--region {arg}: not NAME=X,Y,W,H") from None
    if not sep or not name or w < 1 or h < 1 or x < 0 or y < 0 or x + w > shape[1] or y + h > shape[0]:
        raise InputError(f"--region {arg}: not NAME=X,Y,W,H inside the {shape[1]} x {shape[0]} image")
    return name, (slice(y, y + h), slice(x, x + w))


def weight(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """1 / (m^2 + 0.01), m the halves' mean: relMSE's divisor."""
    return 1.0 / ((0.5 * (a + b)) ** 2 + 0.01)


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance over the channel axis (3 x H x W, or K x 3 x H x W)."""
    return np.tensordot([0.2126, 0.7152, 0.0722], rgb, axes=([0], [-3]))


def split(films: np.ndarray, a: np.ndarray, b: np.ndarray, w: np.ndarray) -> dict[str, np.ndarray]:
    """Per-pixel error maps (H x W) of K films (K x 3 x H x W) against halves a and b."""
    out = {"relmse": ((films - a) * (films - b) * w).mean(0).mean(0)}
    k = films.shape[0]
    if k > 1:
        mu = films.mean(0)
        out["variance"] = (films.var(0, ddof=1) * w).mean(0)
        out["bias2"] = ((mu - a) * (mu - b) * w).mean(0) - out["variance"] / k
    return out


def gate(x: np.ndarray, y: np.ndarray, a: np.ndarray, b: np.ndarray, w: np.ndarray, n: int) -> float:
    """Error less B's noise of the per-block choice between x and y (K x 3 x H x W) made on A."""
    h, wd = a.shape[1:]
    bh, bw = -(-h // n), -(-wd // n)

    def blocks(e: np.ndarray) -> np.ndarray:
        padded = np.zeros((bh * n, bw * n))
        padded[:h, :wd] = e
        return padded.reshape(bh, n, bw, n).sum((1, 3))

    noise_b = float(((a - b) ** 2 / 2 * w).mean())  # E (a - b)^2 / 2 = B's variance
    errors = []
    for xs, ys in zip(x, y):
        pick = blocks(((ys - a) ** 2 * w).mean(0)) < blocks(((xs - a) ** 2 * w).mean(0))
        mask = np.kron(pick, np.ones((n, n)))[:h, :wd]
        mixed = mask * ys + (1 - mask) * xs
        errors.append(float(((mixed - b) ** 2 * w).mean()) - noise_b)
    return float(np.mean(errors))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="denoise_error.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--halves", nargs=2, required=True, metavar=("A.exr", "B.exr"))
    p.add_argument("sets", nargs="+", metavar="NAME=FILM.exr[,FILM.exr...]")
    p.add_argument("--region", action="append", default=[], metavar="NAME=X,Y,W,H")
    p.add_argument("--gate", type=int, metavar="N", help="block side of the per-block choice bound")
    args = p.parse_intermixed_args(argv)
    try:
        if args.gate is not None and args.gate < 1:
            raise InputError(f"--gate {args.gate}: the block side must be 1 or more")
        a, b = read_rgb(args.halves[0]), read_rgb(args.halves[1])
        if a.shape != b.shape:
            raise InputError(f"{args.halves[1]}: {b.shape[2]} x {b.shape[1]}, {args.halves[0]} is "
                             f"{a.shape[2]} x {a.shape[1]}")
        regions = [("image", (slice(None), slice(None)))] + [region_box(r, a.shape[1:]) for r in args.region]
        sets = []
        for s in args.sets:
            name, sep, files = s.partition("=")
            if not sep or not name or not files:
                raise InputError(f"{s}: not NAME=FILM.exr[,FILM.exr...]")
            films = []
            for f in files.split(","):
                x = read_rgb(f)
                if x.shape != a.shape:
                    raise InputError(f"{f}: {x.shape[2]} x {x.shape[1]}, the references are "
                                     f"{a.shape[2]} x {a.shape[1]}")
                films.append(x)
            sets.append((name, np.stack(films)))
        if args.gate is not None and (len(sets) < 2 or sets[0][1].shape != sets[1][1].shape):
            raise InputError("--gate: needs two sets of as many seeds each")
    except InputError as e:
        print(f"denoise_error.py: {e}", file=sys.stderr)
        return 2
    pixels = a.shape[1] * a.shape[2]
    w = weight(a, b)
    ref_lum = luminance(0.5 * (a + b))
    for name, films in sets:
        maps = split(films, a, b, w)
        for region, box in regions:
            e = maps["relmse"][box]
            positive = np.maximum(e, 0.0)
            worst = np.sort(positive.ravel())[::-1][:max(1, e.size // 100)]
            line = {"films": name, "region": region, "seeds": films.shape[0],
                    "pixels": e.size / pixels, "relmse": float(e.sum() / pixels),
                    "top1_share": float(worst.sum() / positive.sum()) if positive.sum() > 0 else None,
                    "lum_ratio": float(luminance(films).mean(0)[box].mean() / ref_lum[box].mean())}
            for key in ("variance", "bias2"):
                if key in maps:
                    line[key] = float(maps[key][box].sum() / pixels)
            print(json.dumps(line))
    if args.gate is not None:
        (nx, x), (ny, y) = sets[0], sets[1]
        print(json.dumps({"films": f"gate({nx}|{ny})", "region": "image", "block": args.gate,
                          "seeds": x.shape[0], "relmse_b": gate(x, y, a, b, w, args.gate),
                          "relmse_b_" + nx: gate(x, x, a, b, w, args.gate),
                          "relmse_b_" + ny: gate(y, y, a, b, w, args.gate)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
