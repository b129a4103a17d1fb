"""Hemisphere-map datasets for training and evaluation: reading `make_dataset.py` folders
(shards of `osr-vk maps`), the network's normalization (DESIGN.md "Normalization", mirrored
from shaders/shared/osr.h) and the 8 symmetries of the square.

Normalization, per map (numbers as in osr_map_normalize.comp):
- m = mean over texels and RGB of the one-shot radiance; the input radiance is
  log(1 + I / (10 m)) - 0.1, the distance log(1 + (z + 1) / (10 (mean z + 1))) - 0.1, the
  normals as traced;
- the target is log(1 + P / (10 m)) with the same m, the input's, so that a noisy target
  (Noise2Noise) does not also scale itself, and the network's output y maps back to radiance
  by 10 m (exp(y) - 1). The renderer then rescales each output channel to the one-shot
  map's channel mean (osr_map_denoise.comp), so the network supplies the shape.
"""
from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

MAP = 32


class DataError(Exception):
    """A dataset the tools cannot use: printed as one line naming the file, exit code 2."""


def load_array(path: Path, shape_tail: tuple[int, ...]) -> np.ndarray:
    """A .npy file as a memmap, checked to be float32 [N, *shape_tail]."""
    try:
        a = np.load(path, mmap_mode="r")
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as e:
        raise DataError(f"{path}: not a readable .npy array ({e})") from None
    if not isinstance(a, np.ndarray):  # np.load opens an .npz archive (a zip) whatever its name
        a.close()
        raise DataError(f"{path}: an .npz archive, not a .npy array")
    if a.dtype != np.float32 or a.ndim != 1 + len(shape_tail) or tuple(a.shape[1:]) != shape_tail:
        raise DataError(f"{path}: shape {list(a.shape)} {a.dtype}, expected [N, "
                        f"{', '.join(map(str, shape_tail))}] float32")
    return a


class Shards:
    """Every shard of one or more dataset folders, read without copies (np.memmap)."""

    def __init__(self, folders: list[str]) -> None:
        self.inputs: list[np.ndarray] = []
        self.targets: list[np.ndarray] = []
        self.scenes: set[int] = set()
        self.spp: set[int] = set()
        for folder in folders:
            path = Path(folder) / "dataset.json"
            try:
                manifest = json.loads(path.read_text())
                self.spp.add(manifest["settings"]["reference_spp"])
                shards = [(Path(folder) / s["path"], int(s["seed"])) for s in manifest["shards"]]
            except (OSError, ValueError, KeyError, TypeError, OverflowError) as e:
                raise DataError(f"{path}: not a make_dataset.py manifest ({e})") from None
            for d, seed in shards:
                x = load_array(d / "input.npy", (7, MAP, MAP))
                y = load_array(d / "target.npy", (3, MAP, MAP))
                if len(x) != len(y):
                    raise DataError(f"{d}: {len(x)} inputs but {len(y)} targets")
                self.inputs.append(x)
                self.targets.append(y)
                self.scenes.add(seed)
        counts = [len(x) for x in self.inputs]
        self.offsets = np.cumsum([0] + counts)
        self.count = int(self.offsets[-1])

    def batch(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rows (global indices) as contiguous float32 arrays [n,7,32,32], [n,3,32,32]."""
        x = np.empty((len(rows), 7, MAP, MAP), np.float32)
        y = np.empty((len(rows), 3, MAP, MAP), np.float32)
        shard = np.searchsorted(self.offsets, rows, side="right") - 1
        for k, (s, r) in enumerate(zip(shard, rows - self.offsets[shard])):
            x[k] = self.inputs[s][r]
            y[k] = self.targets[s][r]
        return x, y

    def load_all(self) -> tuple[np.ndarray, np.ndarray]:
        return self.batch(np.arange(self.count))


def radiance_mean(x: np.ndarray) -> np.ndarray:
    """m per map: mean over texels and RGB of the one-shot radiance, shape [n,1,1,1]."""
    return np.maximum(x[:, 0:3], 0).mean(axis=(1, 2, 3), keepdims=True)


def usable(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Maps the network can learn from: finite, and a one-shot map whose mean is within 100x
    of the target's. About 5 % of interior maps saw almost nothing in their 1024 paths (means
    down to 1e-18 while the target's is normal): normalized by that mean their targets reach
    1e14 and one such map swamps a batch's loss, and no input tells the network their level."""
    m = radiance_mean(x)[:, 0, 0, 0]
    finite = np.isfinite(x).all(axis=(1, 2, 3)) & np.isfinite(y).all(axis=(1, 2, 3))
    return finite & (m > 0) & (np.maximum(y, 0).mean(axis=(1, 2, 3)) <= 100 * m)


def normalize_input(x: np.ndarray) -> np.ndarray:
    m = radiance_mean(x)
    out = np.empty_like(x)
    out[:, 0:3] = np.log1p(np.maximum(x[:, 0:3], 0) / (10 * np.maximum(m, 1e-30))) - 0.1
    out[:, 3:6] = x[:, 3:6]
    zm = x[:, 6:7].mean(axis=(2, 3), keepdims=True)
    out[:, 6:7] = np.log1p((x[:, 6:7] + 1) / (10 * (zm + 1))) - 0.1
    return out


def target_scale(x: np.ndarray) -> np.ndarray:
    """Radiance = target_scale * (exp(y) - 1): 10 m of the one-shot map, [n,1,1,1]."""
    return 10 * np.maximum(radiance_mean(x), 1e-30)


def rescale_to_input(pred: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The renderer's denormalization: each channel scaled to the one-shot map's channel mean
    (a black prediction of a lit map becomes flat at that mean, as in osr_map_denoise)."""
    want = np.maximum(x[:, 0:3], 0).mean(axis=(2, 3), keepdims=True)
    have = pred.mean(axis=(2, 3), keepdims=True)
    safe = np.where(have > 0, have, 1.0)
    return np.where(have > 0, pred * (want / safe), np.broadcast_to(want, pred.shape))


def map_relmse(pred: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Per-map relMSE (epsilon 0.01) of pred against ref, both divided by ref's mean."""
    m = np.maximum(ref.mean(axis=(1, 2, 3), keepdims=True), 1e-30)
    p, r = pred / m, ref / m
    return ((p - r) ** 2 / (r * r + 0.01)).mean(axis=(1, 2, 3))


def symmetry(a: np.ndarray, k: int, normals: bool) -> np.ndarray:
    """Symmetry k in [0, 8) of the square on [n, C, 32, 32]: bit 0 transposes, bit 1 flips x,
    bit 2 flips y. With the cosine-concentric mapping these are the reflections and rotations
    of the map frame about its z axis (tests/osr/test_hemisphere.cpp), so the hit normals in
    channels 3-5 turn with them: a transpose swaps their x and y, a flip of x negates x."""
    out = a
    if k & 1:
        out = out.transpose(0, 1, 3, 2)
        if normals:
            out = out.copy()
            out[:, [3, 4]] = out[:, [4, 3]]
    if k & 2:
        out = out[:, :, :, ::-1]
        if normals:
            out = out.copy()
            out[:, 3] = -out[:, 3]
    if k & 4:
        out = out[:, :, ::-1, :]
        if normals:
            out = out.copy()
            out[:, 4] = -out[:, 4]
    return np.ascontiguousarray(out)


def concentric_directions() -> np.ndarray:
    """Unit direction [3, 32, 32] of each texel centre in the map frame (numpy twin of
    shaders/shared/hemisphere.h's square-to-hemisphere, cosine-weighted concentric)."""
    u = (np.arange(MAP) + 0.5) / MAP
    a = 2 * u[None, :] - 1 + 0 * u[:, None]   # x along columns
    b = 2 * u[:, None] - 1 + 0 * u[None, :]   # y along rows
    big = np.abs(a) > np.abs(b)
    r = np.where(big, a, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(big, np.pi / 4 * b / a, np.pi / 2 - np.pi / 4 * a / b)
    dx, dy = r * np.cos(phi), r * np.sin(phi)
    dz = np.sqrt(np.maximum(0, 1 - dx * dx - dy * dy))
    return np.stack([dx, dy, dz])
