#!/usr/bin/python3
"""Averages independent raw osr-vk renders of one view into a reference that knows its noise.

usage: merge_references.py OUT.exr PART.exr:SPP PART.exr:SPP [...]

Each PART is `osr-vk --mode path --network none --filter none --exr-float` of the same view at
its own --seed (the parts must be independent: two renders of one seed share their samples),
SPP its samples per pixel. OUT holds, as 32-bit float:

- R, G, B: the parts' colour weighted by their samples (the render of all their samples);
- variance.Y: the variance of that mean's luminance, sum of w_i^2 var_i over the parts'
  `variance` layers (as osr-vk writes it for one render);
- spread.R, spread.G, spread.B: the variance of each channel of the mean, estimated from the
  parts' spread around it, sum n_i (c_i - mean)^2 / ((k - 1) N) over k parts of n_i of N
  samples. Unbiased whatever the light paths' colours, and it counts a firefly that the
  per-sample variance of one part can miss. `osr-bench` takes a reference's own noise from it
  (image::referenceNoise, docs/benchmarks.md): with 2 parts each pixel's estimate has one
  degree of freedom, but their mean over an image is close.
- direct.R, ..., indirect.B and their spread (direct.spread.R, ...): the same for the parts'
  `direct` and `indirect` layers (docs/pathtracer.md "Film layers"), where every part has
  them, so that `osr-bench osr-error` can split a bias by layer.

Bad input (a missing or unreadable part, no variance layer, parts of other sizes, fewer than
two parts or one part twice, a bad SPP, an OUT that cannot be written) is one line on stderr
and exit 2; OUT is written only when all is well.
"""
from __future__ import annotations

import sys
import zlib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import exr_file  # noqa: E402

FLOAT = 2  # OpenEXR pixel type


class MergeError(Exception):
    pass


LAYERS = ("direct", "indirect")  # merged, with their spread, where every part has them


def read_part(arg: str) -> tuple[int, np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    path, sep, spp = arg.rpartition(":")
    if not sep or not spp.isdigit() or int(spp) < 1:
        raise MergeError(f"{arg}: not PART.exr:SPP with SPP a positive whole number")
    try:
        header, raw = exr_file.read_raw(path)
    except exr_file.ExrError as e:
        raise MergeError(str(e)) from None  # names the file already
    except (OSError, zlib.error, ValueError) as e:
        raise MergeError(f"{path}: cannot read ({e})") from None
    types = dict(header["channels"])
    missing = [c for c in ("R", "G", "B", "variance.Y") if c not in types]
    if missing:
        raise MergeError(f"{path}: no {', '.join(missing)} channel (not a raw osr-vk render)")
    if "noisy.R" in types:
        raise MergeError(f"{path}: a denoised render (it has a noisy layer); render the parts with "
                         "--network none --filter none")
    channel = lambda c: exr_file.to_float(types[c], raw[c]).astype(np.float64)  # noqa: E731
    layers = {name: np.stack([channel(f"{name}.{c}") for c in "RGB"]) for name in LAYERS
              if all(f"{name}.{c}" in types for c in "RGB")}
    return int(spp), np.stack([channel(c) for c in "RGB"]), channel("variance.Y"), layers


def mean_and_spread(spp: np.ndarray, colours: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sample-weighted mean of k independent parts (k x ... arrays, spp their samples) and
    the unbiased variance of that mean from their spread, sum n_i (c_i - mean)^2 / ((k - 1) N).
    train_denoiser.py takes its validation references' noise from it too."""
    spp = np.asarray(spp, np.float64)
    mean = np.tensordot(spp / spp.sum(), colours, 1)
    spread = np.tensordot(spp, (colours - mean) ** 2, 1) / ((len(spp) - 1) * spp.sum())
    return mean, spread


def merge(parts: list[tuple[int, np.ndarray, np.ndarray, dict[str, np.ndarray]]]) -> dict[str, np.ndarray]:
    spp = np.array([p[0] for p in parts], np.float64)
    w = spp / spp.sum()
    mean, spread = mean_and_spread(spp, np.stack([p[1] for p in parts]))
    variance = np.tensordot(w * w, np.stack([p[2] for p in parts]), 1)
    out = {c: mean[i] for i, c in enumerate("RGB")}
    out["variance.Y"] = variance
    out.update({f"spread.{c}": spread[i] for i, c in enumerate("RGB")})
    for name in LAYERS:
        if all(name in p[3] for p in parts):
            mean, spread = mean_and_spread(spp, np.stack([p[3][name] for p in parts]))
            out.update({f"{name}.{c}": mean[i] for i, c in enumerate("RGB")})
            out.update({f"{name}.spread.{c}": spread[i] for i, c in enumerate("RGB")})
    return out


def main(argv: list[str]) -> int:
    if argv[:1] in (["-h"], ["--help"]):
        print(__doc__.strip())
        return 0
    if len(argv) < 3:
        print("usage: merge_references.py OUT.exr PART.exr:SPP PART.exr:SPP [...] (at least two parts; --help)",
              file=sys.stderr)
        return 2
    out, args = argv[0], argv[1:]
    try:
        paths = [Path(a.rpartition(":")[0]).resolve() for a in args]
        if Path(out).resolve() in paths:
            raise MergeError(f"{out}: is also a part (the output may not overwrite an input)")
        twice = next((a for a, p in zip(args, paths) if paths.count(p) > 1), None)
        if twice is not None:
            raise MergeError(f"{twice}: given twice (the parts must be independent renders)")
        parts = [read_part(a) for a in args]
        shapes = {p[1].shape for p in parts}
        if len(shapes) != 1:
            raise MergeError(f"{args[0]}: parts of different sizes ({', '.join(f'{s[2]}x{s[1]}' for s in shapes)})")
        channels = {name: (FLOAT, a.astype(np.float32).view(np.uint32)) for name, a in merge(parts).items()}
        try:
            exr_file.write_raw(out, channels)
        except OSError as e:
            raise MergeError(f"{out}: cannot write ({e.strerror})") from None
    except MergeError as e:
        print(f"merge_references.py: {e}", file=sys.stderr)
        return 2
    spp = sum(p[0] for p in parts)
    print(f"{out}: {spp} spp from {len(parts)} parts")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
