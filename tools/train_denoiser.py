#!/usr/bin/python3
"""Trains the image denoiser (tools/image_unet.py: "osr_image_kpn_v2", the kernel predictor
whose kernels are multiplied by fixed normal and depth edge-stopping factors; with --arch kpn
"osr_image_kpn_v1", without them; with --arch unet the direct "osr_image_unet_v1") on noisy
renders.

usage: train_denoiser.py DATA [DATA ...] --val VAL --out RUN [--arch kpn4|kpn3|kpn2|kpn|unet] [--k 16]
                         [--steps N | --minutes M]
                         [--resume] [--batch 8] [--crop 64] [--lr 2e-3] [--threads 2] [--device cpu]
                         [--loss-scale output|filter] [--loss-cap C]
                         [--quick]

DATA and VAL are make_denoise_data.py folders; VAL holds other interiors than DATA, with
references (make_denoise_data.py VAL --validation). The run folder RUN gets:
- checkpoint.pt: model, optimizer, step, elapsed time, written atomically every
  --checkpoint-s seconds; `--resume` continues from it (without --resume an existing one is
  refused, so a run is never overwritten by accident);
- best.pt: the weights with the lowest validation error, as a dict {"model": state_dict,
  "architecture": "osr_image_kpn_v1", "base_width": K, "epoch", "step", "loss",
  "val_relmse", ...} with the training metadata (the packer's input);
- final.pt: the same for the moving average at the end of the run (what the default ships:
  on three views best.pt can win by noise, docs/training.md "Image denoiser");
- train.log: one JSON object per validation (step, epoch, losses, relMSE per input spp,
  crops/s); eval.json: the last validation of best.pt.

Examples: every render of a view is independent, so a random subset of them, averaged with
their sample counts as weights, is a noisy input of that many samples, and the others'
average an independent noisy target with the same expectation (Noise2Noise). The input's
sample count is drawn log-uniformly over the counts the subsets reach, keeping the target at
least a quarter of the input's samples; a view with a reference (ref_*.npz) uses it as the
target instead. Albedo, normal and depth are averaged over the input's renders as the
renderer averages them (a view rendered before depth was kept has one depth.npz for all its
renders; kpn2-kpn4 need depth, the others do not read it; kpn3 and kpn4 also the renders' variance
layer, the variance of the mean being the sum of w_i^2 var_i over the averaged renders). The exposure e is computed on the whole input image (as the renderer does),
then a random crop (a multiple of 8) is taken and one of the 8 symmetries of the square
applied to colour, albedo, normal and target alike. Normals are world-space directions:
turning or mirroring the image does not turn them, so their values are moved with the
pixels but not changed.

Loss: relative MSE on linear colour scaled by the exposure, mean over pixels and channels of
(y - t)^2 / (sg(y)^2 + 0.01) with y the denoised colour times e (for the direct variant
y = expm1(out) unclamped, so a pixel whose output starts below zero still gets a gradient;
the renderer clamps it), t the target times e and sg no gradient
(Lehtinen et al. 2018: mean-seeking, so noisy targets train towards their expectation).
--loss-scale filter divides by the a-trous filter's image of the same input in place of
sg(y): a divisor that does not move with the weights (measured no better on the renderer's
films, docs/training.md "Nor an error relative to the filter's image").
--loss-cap C counts a pixel's relative error r = |y - t| / sqrt(d^2 + 0.01), d the divisor
--loss-scale chose, beyond C linearly (Huber: 2 C r - C^2 in place of r^2), so a target's
firefly pulls with a bounded gradient; it is no longer mean-seeking there, and measured
darkens scenes lit by small lamps (docs/training.md "Nor a capped loss").
Adam with a cosine learning-rate decay over the budget; gradient norm clipped at 1 (a noisy
target's rare bright path still makes a large relative loss now and then). The noisy targets
make single steps noisy too, so the weights validated and saved are a running average
(--ema, 0.99 per step: about the last hundred steps).

Validation: every view of VAL at each of its input sample counts, the whole image, relMSE
(epsilon 0.01, linear colour, as `osr-vk compare`) of the network's output (as the renderer
computes it: image_unet.denoise) against the reference, and of the noisy input for comparison.
val_reference_noise estimates what the reference's own noise adds to each figure (from the
highest-spp input, independent of the reference: v_in + v_ref with v_in = v_ref m / n).
Where a view's reference has several chunks (make_denoise_data.py --validation), their
spread gives its noise exactly (val_chunk_reference_noise, unbiased per channel) and
val_less_ref_relmse_Nspp (and _filter_ for the filter) are the figures less it: estimates of
the error against the converged image, which tell models apart at 64 spp and up where the
reference's noise is most of every figure. best.pt is chosen by val_select: the geometric mean
of those at the sample counts trained for (at least --min-spp), or without chunks the
geometric mean over views and sample counts (val_relmse_geomean, so 1 spp does not drown the
rest); val_relmse is the plain mean.

--quick: a tiny synthetic dataset of its own under RUN/synthetic (DATA and --val may then be
omitted), K=4, a few steps of 16 x 16 crops: seconds; what tests/tools/test_denoiser_training.py
runs. Its model is not for shipping.
"""
from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from arg_types import positive_float, positive_int  # noqa: E402
from merge_references import mean_and_spread  # noqa: E402

RELMSE_EPSILON = 0.01  # as osr-vk compare (src/image/image_metrics.h)
SELECT_METRIC = "val_select"  # what best.pt is chosen by (a resumed run of another starts afresh)
MIN_TARGET_SHARE = 0.25  # a Noise2Noise target keeps at least this share of the input's spp
ARCHS = {"kpn4": "osr_image_kpn_v4", "kpn3": "osr_image_kpn_v3", "kpn2": "osr_image_kpn_v2", "kpn": "osr_image_kpn_v1", "unet": "osr_image_unet_v1"}  # image_unet's


class DataError(Exception):
    """A dataset or checkpoint that cannot be used; the message names it."""


def git_commit() -> str:
    try:
        return subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


class View:
    """One camera view: its independent noisy renders and, where it has one, the reference."""

    def __init__(self, folder: Path) -> None:
        self.name = folder.name
        inputs = sorted(folder.glob("in_*.npz"), key=lambda p: int(p.name.split("_")[1]))
        # One file per reference chunk: a chunk rendered again with more samples (a larger
        # --target-spp) has the same seed, so only the larger of the two counts.
        refs_by_chunk: dict[int, Path] = {}
        for ref in folder.glob("ref_*.npz"):
            k, n = (int(t) for t in ref.stem.split("_")[1:3])
            if k not in refs_by_chunk or n > int(refs_by_chunk[k].stem.split("_")[2]):
                refs_by_chunk[k] = ref
        refs = [refs_by_chunk[k] for k in sorted(refs_by_chunk)]
        if not inputs:
            raise DataError(f"{folder}: no in_*.npz renders")
        renders = [self._load(p) for p in inputs]
        self.spp = np.array([int(r["spp"]) for r in renders], np.int64)
        self.colour = np.stack([r["colour"] for r in renders])  # R x 3 x H x W float32
        self.albedo = np.stack([r["albedo"] for r in renders]).astype(np.float32)
        self.normal = np.stack([r["normal"] for r in renders]).astype(np.float32)
        # Depth per render, else the view's depth.npz for all of them (make_denoise_data.py),
        # else none (R x 1 x H x W).
        self.depth = self._guide(folder, renders, "depth")
        # The renderer's variance of each pixel's luminance estimate per render (R x 1 x H x W),
        # where the renders kept it (osr_image_kpn_v3 needs it).
        self.variance = None
        if all("variance" in r for r in renders):
            self.variance = np.stack([r["variance"] for r in renders]).astype(np.float32)
        # The share of each pixel's camera rays that saw light directly, likewise (none: no pixel
        # kept out).
        self.light = self._guide(folder, renders, "light")
        # Validation renders also keep the a-trous filter's image of each render.
        self.filtered = None
        if all("filtered" in r for r in renders):
            self.filtered = np.stack([r["filtered"] for r in renders])
        self.ref = None
        self.ref_spp = 0
        self.ref_noise = None
        if refs:
            loaded = [self._load(p) for p in refs]
            weights = np.array([int(r["spp"]) for r in loaded], np.float64)
            chunks = np.stack([r["colour"] for r in loaded]).astype(np.float64)
            self.ref_spp = int(weights.sum())
            if len(loaded) > 1:
                # What the reference's own noise adds to a relMSE against it: the variance of
                # its mean per pixel and channel, from the spread of its independent chunks
                # (unbiased, merge_references.mean_and_spread), over ref^2 + epsilon.
                mean, spread = mean_and_spread(weights, chunks)
                self.ref_noise = float(np.mean(spread / (mean ** 2 + RELMSE_EPSILON)))
            else:
                mean = chunks[0]
            self.ref = mean.astype(np.float32)
        shapes = {a.shape[-2:] for a in (self.colour, self.albedo, self.normal)
                  + ((self.depth,) if self.depth is not None else ())}
        if len(shapes) != 1 or (self.ref is not None and self.ref.shape[-2:] not in shapes):
            raise DataError(f"{folder}: renders of different sizes")
        self.height, self.width = self.colour.shape[-2:]
        # The subsets usable as an input: proper (a target is left) unless a reference exists.
        total = int(self.spp.sum())
        self.subsets: dict[int, list[tuple[int, ...]]] = {}
        for n in range(1, len(self.spp) + 1):
            for s in itertools.combinations(range(len(self.spp)), n):
                spp = int(self.spp[list(s)].sum())
                if self.ref is None and total - spp < MIN_TARGET_SHARE * spp:
                    continue
                self.subsets.setdefault(spp, []).append(s)
        self.levels = np.array(sorted(self.subsets), np.int64)

    @staticmethod
    def _guide(folder: Path, renders: list[dict], key: str) -> np.ndarray | None:
        """A guide layer (R x 1 x H x W float32) from every render, else from the view's KEY.npz
        (one render for all, make_denoise_data.py), else None."""
        if all(key in r for r in renders):
            return np.stack([r[key] for r in renders]).astype(np.float32)
        if not (folder / f"{key}.npz").is_file():
            return None
        try:
            with np.load(folder / f"{key}.npz") as z:
                guide = z[key].astype(np.float32)
        except (OSError, ValueError, KeyError, EOFError) as e:
            raise DataError(f"{folder / f'{key}.npz'}: not a make_denoise_data.py {key} render ({e})") from None
        return np.broadcast_to(guide, (len(renders), *guide.shape))

    @staticmethod
    def _load(path: Path) -> dict:
        try:
            with np.load(path) as z:
                out = {k: z[k] for k in ("spp", "colour", "albedo", "normal")}
                for optional in ("depth", "variance", "filtered", "light"):
                    if optional in z.files:
                        out[optional] = z[optional]
                return out
        except (OSError, ValueError, KeyError, EOFError) as e:
            raise DataError(f"{path}: not a make_denoise_data.py render ({e})") from None

    def _weights(self, idx: list[int]) -> np.ndarray:
        """Each of renders idx's share of their summed samples."""
        w = self.spp[idx].astype(np.float32)
        return w / w.sum()

    def colour_mean(self, idx: list[int]) -> np.ndarray:
        """The spp-weighted mean colour of renders idx (a Noise2Noise target needs no guides)."""
        return np.tensordot(self._weights(idx), self.colour[idx], 1)

    def mean(self, idx: list[int]) -> tuple[np.ndarray, ...]:
        """The spp-weighted mean of renders idx: colour, albedo, normal, depth (zeros when the
        view has none), the variance of the mean's luminance (sum of w_i^2 var_i over the
        independent renders; zeros when the view has none) and the share of light seen
        directly (zeros when the view has none)."""
        w = self._weights(idx)
        depth = self.depth if self.depth is not None else np.zeros_like(self.colour[:, :1])
        variance = self.variance if self.variance is not None else np.zeros_like(self.colour[:, :1])
        light = self.light if self.light is not None else np.zeros_like(self.colour[:, :1])
        means = tuple(np.tensordot(w, a[idx], 1) for a in (self.colour, self.albedo, self.normal, depth))
        return (*means, np.tensordot(w * w, variance[idx], 1), np.tensordot(w, light[idx], 1))

    def example(self, rng: np.random.Generator, min_spp: int = 1) -> tuple[np.ndarray, ...]:
        """A random (input colour, albedo, normal, depth, variance, target colour, input spp,
        input light share), whole images, of at least min_spp samples where the view reaches that many."""
        # Log-uniform over the reachable sample counts: the nearest level to exp(u).
        levels = self.levels[self.levels >= min_spp]
        if not len(levels):
            levels = self.levels[-1:]
        u = rng.uniform(math.log(levels[0]), math.log(levels[-1] + 0.5))
        level = int(levels[np.abs(np.log(levels) - u).argmin()])
        choices = self.subsets[level]
        chosen = list(choices[int(rng.integers(len(choices)))])
        colour, albedo, normal, depth, variance, light = self.mean(chosen)
        if self.ref is not None:
            target = self.ref
        else:
            rest = [i for i in range(len(self.spp)) if i not in chosen]
            target = self.colour_mean(rest)
        return colour, albedo, normal, depth, variance, target, level, light


class Dataset:
    """The complete views of make_denoise_data.py folders; reload() picks up views that were
    completed since (a dataset still being rendered)."""

    def __init__(self, folders: list[str], with_reference: bool = False, need_depth: bool = False,
                 need_variance: bool = False) -> None:
        self.folders = [Path(f) for f in folders]
        self.with_reference = with_reference
        self.need_depth = need_depth
        self.need_variance = need_variance
        for f in self.folders:
            if not (f / "dataset.json").is_file():
                raise DataError(f"{f}: no dataset.json (not a make_denoise_data.py folder)")
        self.views: dict[str, View] = {}
        self.reload()

    def reload(self) -> int:
        added = 0
        for folder in self.folders:
            manifest = json.loads((folder / "dataset.json").read_text())
            wanted = len(manifest.get("spp_list", [])) or 1
            for name in sorted(manifest.get("views", {})):
                key = f"{folder}/{name}"
                if key in self.views:
                    continue
                view_dir = folder / name
                if len(list(view_dir.glob("in_*.npz"))) < wanted:
                    continue  # still being rendered
                if self.with_reference and not any(view_dir.glob("ref_*.npz")):
                    continue
                view = View(view_dir)
                if self.need_depth and view.depth is None:
                    raise DataError(f"{view_dir}: no depth (renders from before depth was kept: run "
                                    "make_denoise_data.py on the folder again to add depth.npz)")
                if self.need_variance and view.variance is None:
                    raise DataError(f"{view_dir}: no variance (renders from before osr-vk wrote its "
                                    "variance layer: render the folder again)")
                self.views[key] = view
                added += 1
        self.keys = sorted(self.views)
        return added

    def scenes(self) -> set[int]:
        return {int(Path(k).name.split("_")[0]) for k in self.keys}

    def pixels(self) -> int:
        return sum(v.height * v.width for v in self.views.values())


def symmetry(a: np.ndarray, k: int) -> np.ndarray:
    """One of the 8 symmetries of the square on the last two axes (k: 0-7). Only pixels move:
    the caller passes normals through it too, unchanged, since they are world-space."""
    if k & 4:
        a = a[..., ::-1]
    return np.rot90(a, k & 3, axes=(-2, -1))


def make_batch(data: Dataset, rng: np.random.Generator, batch: int, crop: int, device: str = "cpu",
               min_spp: int = 1):
    """(colour, albedo, normal, depth, variance, e, target) tensors of `batch` random crops on
    `device`, the mean input spp and the light share's tensor."""
    import torch
    from image_unet import image_exposure
    colours, albedos, normals, depths, variances, targets, lights, es, spps = [], [], [], [], [], [], [], [], []
    for _ in range(batch):
        view = data.views[data.keys[int(rng.integers(len(data.keys)))]]
        colour, albedo, normal, depth, variance, target, spp, light = view.example(rng, min_spp)
        es.append(image_exposure(torch.from_numpy(colour)[None]))
        size = min(crop, view.height, view.width) // 8 * 8
        y0 = int(rng.integers(view.height - size + 1))
        x0 = int(rng.integers(view.width - size + 1))
        k = int(rng.integers(8))
        window = (slice(None), slice(y0, y0 + size), slice(x0, x0 + size))
        for out, a in ((colours, colour), (albedos, albedo), (normals, normal), (depths, depth),
                       (variances, variance), (targets, target), (lights, light)):
            out.append(np.ascontiguousarray(symmetry(a[window], k)))
        spps.append(spp)
    e = torch.cat(es).to(device)
    tensors = [torch.from_numpy(np.stack(a)).to(device)
               for a in (colours, albedos, normals, depths, variances, targets, lights)]
    return (*tensors[:5], e, tensors[5], float(np.mean(spps)), tensors[6])


def filter_image(model, colour, albedo, normal, depth, variance, e, light=None):
    """The a-trous filter's image of the input: the kernels with zero logits (kpn3, kpn4)."""
    import torch
    import image_unet
    n, _, h, w = colour.shape
    zero = torch.zeros(n, image_unet.KPN_OUT_CHANNELS, h, w, dtype=colour.dtype, device=colour.device)
    with torch.no_grad():
        return image_unet.apply_kernels(zero, colour, albedo, e, light, guides=(normal, depth), variance=variance,
                                        straddle=model.architecture == image_unet.STRADDLE_ARCHITECTURE)


def loss_fn(model, colour, albedo, normal, depth, variance, e, target, scale_by: str = "output", light=None,
            cap: float = 0.0):
    import torch
    import image_unet
    scale = e.view(-1, 1, 1, 1)
    if model.architecture in image_unet.KERNEL_ARCHITECTURES:
        y = image_unet.denoise(model, colour, albedo, normal, e, depth, variance, light) * scale
    else:
        x, _ = image_unet.make_input(colour, albedo, normal, e)
        y = torch.expm1(model(x))  # exposure-scaled colour, unclamped (see the docstring)
    t = target * scale
    # Each pixel's error relative to an estimate of its colour: the network's own output
    # (Lehtinen et al.), or the filter's image of the same input, which does not move with the
    # weights (see the docstring).
    if scale_by == "output":
        d = y.detach()
    else:
        d = filter_image(model, colour, albedo, normal, depth, variance, e, light) * scale
    r2 = (y - t) ** 2 / (d ** 2 + RELMSE_EPSILON)
    return (huber(r2, cap) if cap > 0 else r2).mean()


def huber(r2, cap: float):
    """r^2 up to cap^2, 2 cap r - cap^2 beyond: each pixel's squared relative error r^2 with
    the part beyond cap counted linearly. The root is taken of r^2 clamped to the linear side
    only: where r^2 is 0 its gradient would be infinite, and 0 times that is NaN."""
    import torch
    return torch.where(r2 < cap * cap, r2, 2 * cap * torch.sqrt(r2.clamp(min=cap * cap)) - cap * cap)


def relmse(a: np.ndarray, ref: np.ndarray) -> float:
    return float(np.mean((a.astype(np.float64) - ref) ** 2 / (ref.astype(np.float64) ** 2 + RELMSE_EPSILON)))


def denoise(model, colour: np.ndarray, albedo: np.ndarray, normal: np.ndarray, depth: np.ndarray,
            variance: np.ndarray, light: np.ndarray | None = None) -> np.ndarray:
    """The network's colour for one whole image (3 x H x W, depth, variance and light 1 x H x W,
    H and W multiples of 8)."""
    import torch
    import image_unet
    device = next(model.parameters()).device
    with torch.no_grad():
        c, a, n, z, v = (torch.from_numpy(np.ascontiguousarray(x))[None].to(device)
                         for x in (colour, albedo, normal, depth, variance))
        lit = None if light is None else torch.from_numpy(np.ascontiguousarray(light))[None].to(device)
        return image_unet.denoise(model, c, a, n, depth=z, variance=v, light=lit)[0].cpu().numpy()


def evaluate(model, val: Dataset, min_spp: int = 1) -> dict:
    """relMSE of the network and of its noisy input against the reference, per input spp, and
    of the a-trous filter's image where the validation renders kept it."""
    model.eval()
    net: dict[int, list[float]] = {}
    noisy: dict[int, list[float]] = {}
    filtered: dict[int, list[float]] = {}
    ref_noise = []
    net_less_ref: dict[int, list[float]] = {}
    filtered_less_ref: dict[int, list[float]] = {}
    select: dict[int, list[float]] = {}
    for key in val.keys:
        view = val.views[key]
        # The reference's own noise is in every figure: for the independent input of n
        # samples against a reference of m, E[relMSE] ~ v_in + v_ref with v_in = v_ref m / n.
        top = int(view.spp.argmax())
        ref_noise.append(relmse(view.colour[top], view.ref) / (view.ref_spp / view.spp[top] + 1))
        for i, spp in enumerate(view.spp.tolist()):
            colour, albedo, normal, depth, variance, light = view.mean([i])
            net.setdefault(spp, []).append(relmse(denoise(model, colour, albedo, normal, depth, variance, light),
                                                  view.ref))
            if view.ref_noise is not None:
                net_less_ref.setdefault(spp, []).append(net[spp][-1] - view.ref_noise)
                # For the choice of best.pt, floored at a tenth of the reference's noise: less
                # that noise a figure can come out near or below zero, and one view there
                # would decide a geometric mean.
                select.setdefault(spp, []).append(max(net_less_ref[spp][-1], 0.1 * view.ref_noise))
            noisy.setdefault(spp, []).append(relmse(colour, view.ref))
            if view.filtered is not None:
                filtered.setdefault(spp, []).append(relmse(view.filtered[i], view.ref))
                if view.ref_noise is not None:
                    filtered_less_ref.setdefault(spp, []).append(filtered[spp][-1] - view.ref_noise)
    model.train()
    every = [v for vs in net.values() for v in vs]
    out = {"val_relmse": float(np.mean(every)),
           "val_relmse_geomean": float(np.exp(np.mean(np.log(np.maximum(every, 1e-12))))),
           "val_reference_noise": float(np.mean(ref_noise))}
    if net_less_ref and all(len(net_less_ref.get(spp, ())) == len(net[spp]) for spp in net):
        # The same less each view's reference noise from its chunks' spread: an unbiased
        # estimate of the error against the true image, what tells models apart at 64 spp and up.
        out["val_chunk_reference_noise"] = float(np.mean([val.views[k].ref_noise for k in val.keys]))
        for spp in sorted(net_less_ref):
            out[f"val_less_ref_relmse_{spp}spp"] = float(np.mean(net_less_ref[spp]))
        # best.pt's choice: the geometric mean of these at the sample counts trained for.
        chosen = [v for spp, vs in select.items() if spp >= min_spp for v in vs] or \
            [v for vs in select.values() for v in vs]
        out["val_select"] = float(np.exp(np.mean(np.log(chosen))))
    for spp in sorted(net):
        out[f"val_relmse_{spp}spp"] = float(np.mean(net[spp]))
        out[f"val_noisy_relmse_{spp}spp"] = float(np.mean(noisy[spp]))
    if filtered and len(filtered) == len(net):
        every_filtered = [v for vs in filtered.values() for v in vs]
        out["val_filter_relmse_geomean"] = float(np.exp(np.mean(np.log(np.maximum(every_filtered, 1e-12)))))
        out["val_over_filter_geomean"] = out["val_relmse_geomean"] / out["val_filter_relmse_geomean"]
        for spp in sorted(filtered):
            out[f"val_filter_relmse_{spp}spp"] = float(np.mean(filtered[spp]))
            if len(filtered_less_ref.get(spp, ())) == len(filtered[spp]):
                out[f"val_less_ref_filter_relmse_{spp}spp"] = float(np.mean(filtered_less_ref[spp]))
    out.setdefault("val_select", out["val_relmse_geomean"])
    return out


def save_atomic(obj, path: Path) -> None:
    import torch
    tmp = path.with_name(path.name + ".tmp")
    torch.save(obj, tmp)
    os.replace(tmp, path)


def write_synthetic(folder: Path, seed: int, views: int, size: int, spp_list: list[int], ref_spp: int) -> None:
    """A tiny make_denoise_data.py-shaped dataset of smooth images with Poisson-like noise
    (--quick and the tests): random boxes of colour, albedo and normal, the colour lit by a
    smooth gradient, each render its own noise at its sample count."""
    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    manifest = {"format": "osr-vk denoise data", "size": size, "spp_list": spp_list, "target_spp": ref_spp,
                "validation": ref_spp > 0, "synthetic": True, "views": {}}
    yy, xx = np.mgrid[0:size, 0:size] / size
    for v in range(views):
        albedo = np.full((3, size, size), 0.5, np.float32)
        normal = np.zeros((3, size, size), np.float32)
        normal[1] = 1
        depth = (2.0 + xx)[None].astype(np.float32)
        for _ in range(4):
            y0, x0 = rng.integers(0, size - 4, 2)
            h, w = rng.integers(4, size // 2, 2)
            albedo[:, y0:y0 + h, x0:x0 + w] = rng.uniform(0.1, 0.9, (3, 1, 1))
            n = rng.normal(size=3)
            normal[:, y0:y0 + h, x0:x0 + w] = (n / np.linalg.norm(n))[:, None, None]
            depth[:, y0:y0 + h, x0:x0 + w] -= rng.uniform(0.2, 1.0)
        light = (0.5 + xx + 0.5 * yy).astype(np.float32)
        clean = albedo * light
        name = f"{seed * 100 + v}_c0"
        (folder / name).mkdir(exist_ok=True)

        def write(file: str, spp: int) -> None:
            noisy = rng.gamma(spp, 1.0 / spp, clean.shape).astype(np.float32) * clean
            lum = 0.2126 * clean[0] + 0.7152 * clean[1] + 0.0722 * clean[2]
            np.savez(folder / name / file, spp=np.int32(spp), seed=np.int64(0), seconds=np.float32(0),
                     variance=(lum * lum / spp)[None].astype(np.float32),
                     colour=noisy, albedo=albedo.astype(np.float16), normal=normal.astype(np.float16), depth=depth)
        for i, spp in enumerate(spp_list):
            write(f"in_{i}_{spp}.npz", spp)
        if ref_spp:  # two independent chunks, as make_denoise_data.py --validation writes
            write(f"ref_0_{ref_spp}.npz", ref_spp)
            write(f"ref_1_{ref_spp}.npz", ref_spp)
        manifest["views"][name] = {"seed": seed * 100 + v, "camera": 0, "seconds": 0.0}
    (folder / "dataset.json").write_text(json.dumps(manifest, indent=1) + "\n")


def progress_line(frac: float, step: int, epoch: float, loss: float, rate: float, val: float | None,
                  remaining: float) -> str:
    bar = "#" * int(frac * 24) + "-" * (24 - int(frac * 24))
    v = f" val {val:.4f}" if val is not None else ""
    return (f"\r[{bar}] {100 * frac:5.1f}% step {step} epoch {epoch:.2f} loss {loss:.4f}{v} "
            f"{rate:.1f} crops/s, {int(remaining // 60)}:{int(remaining % 60):02d} left ")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="train_denoiser.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("data", nargs="*", help="training dataset folders (make_denoise_data.py)")
    p.add_argument("--val", help="validation folder (other interiors, with references)")
    p.add_argument("--out", required=True, help="run folder")
    p.add_argument("--resume", action="store_true", help="continue the run in --out from its checkpoint.pt")
    p.add_argument("--init", metavar="CHECKPOINT",
                   help="start from this checkpoint's weights (a best.pt of the same width, or a packed .osrw "
                   "such as models/osr_image_denoiser.osrw; the kernel architectures share their weights, "
                   "so a trained kpn model can start a kpn2 run)")
    p.add_argument("--arch", choices=tuple(ARCHS), default="kpn2",
                   help="kpn4: kpn3 with the normal factor of a pixel that straddles an edge taken on the "
                   "mean normals, as the a-trous filter does; kpn3: the kernels of kpn2 times the a-trous filter's B3-spline and variance-scaled "
                   "luminance factors, so the network starts as the filter and learns what it misses; "
                   "kpn2: the network predicts filter kernels, multiplied by fixed normal and depth "
                   "edge-stopping factors (default); kpn: without them; unet: it predicts the colour")
    p.add_argument("--k", type=positive_int, default=16, help="base width K of the U-Net (default 16)")
    p.add_argument("--minutes", type=positive_float, default=30.0, help="training time budget (default 30)")
    p.add_argument("--steps", type=positive_int, help="a budget in steps instead of time")
    p.add_argument("--batch", type=positive_int, default=8, help="crops per step (default 8)")
    p.add_argument("--crop", type=positive_int, default=64, help="crop size, a multiple of 8 (default 64)")
    p.add_argument("--min-spp", type=positive_int, default=1,
                   help="train on inputs of at least this many samples per pixel (default 1): the sample "
                   "counts a render of seconds reaches, which few-sample examples otherwise outweigh")
    p.add_argument("--lr", type=positive_float, default=2e-3, help="initial Adam learning rate (default 2e-3)")
    p.add_argument("--threads", type=positive_int, default=2, help="PyTorch CPU threads (default 2)")
    p.add_argument("--device", default="cpu",
                   help="where the network trains: cpu, or cuda (a GPU; the batches are still made on the "
                   "CPU) (default cpu)")
    p.add_argument("--loss-scale", choices=["output", "filter"], default="output",
                   help="what each pixel's squared error is relative to: the network's output or the "
                        "a-trous filter's image of the input (kpn3, kpn4; default output)")
    p.add_argument("--loss-cap", type=positive_float, default=0.0, metavar="C",
                   help="count each pixel's relative error beyond C linearly (Huber; default: no cap)")
    p.add_argument("--ema", type=float, default=0.99,
                   help="decay of the weights' running average, which is validated and saved (default 0.99)")
    p.add_argument("--seed", type=int, default=1, help="seed of initialization and batches (default 1)")
    p.add_argument("--eval-s", type=positive_float, default=300.0, help="seconds between validations (default 300)")
    p.add_argument("--checkpoint-s", type=positive_float, default=60.0,
                   help="seconds between checkpoints (default 60)")
    p.add_argument("--reload-s", type=positive_float, default=600.0,
                   help="seconds between looks for newly rendered views in DATA (default 600)")
    p.add_argument("--quick", action="store_true", help="a tiny synthetic dataset and a few steps (tests)")
    p.add_argument("--evaluate", metavar="CHECKPOINT",
                   help="no training: validate this checkpoint on --val, write RUN/eval.json")
    p.add_argument("--record", metavar="JSON",
                   help="with --evaluate: also write the checkpoint's metadata and figures here (models/*.json)")
    args = p.parse_args(argv)
    if args.crop % 8:
        p.error(f"argument --crop: must be a multiple of 8, got {args.crop}")
    if not 0 <= args.ema < 1:
        p.error(f"argument --ema: must be in [0, 1), got {args.ema}")

    import torch
    import image_unet
    torch.set_num_threads(args.threads)
    if args.device != "cpu":
        try:
            torch.empty(1, device=args.device)
        except (RuntimeError, AssertionError) as e:
            print(f"train_denoiser.py: --device {args.device}: not usable here ({str(e).splitlines()[0]})",
                  file=sys.stderr)
            return 2
    run = Path(args.out)
    ckpt_path, best_path, log_path = run / "checkpoint.pt", run / "best.pt", run / "train.log"
    final_path = run / "final.pt"
    if ckpt_path.is_file() and not args.resume and not args.evaluate:
        print(f"train_denoiser.py: {ckpt_path} exists: pass --resume to continue it, or another --out",
              file=sys.stderr)
        return 2
    if args.resume and not ckpt_path.is_file():
        print(f"train_denoiser.py: --resume: {ckpt_path} does not exist", file=sys.stderr)
        return 2
    if args.quick:
        synthetic = run / "synthetic"
        if not args.data:
            write_synthetic(synthetic / "train", 1, 4, 32, [1, 2, 4], 0)
            args.data = [str(synthetic / "train")]
        if not args.val:
            write_synthetic(synthetic / "val", 2, 1, 32, [1, 4], 64)
            args.val = str(synthetic / "val")
        if args.steps is None:
            args.steps = 6
        args.k, args.batch, args.crop = min(args.k, 4), min(args.batch, 2), min(args.crop, 16)
        args.ema = min(args.ema, 0.5)
    if not args.val or not (args.data or args.evaluate):
        p.error("DATA and --val are required (unless --quick; --evaluate needs only --val)")
    if args.evaluate:
        return evaluate_checkpoint(args.evaluate, args.val, run, args.record)
    architecture = ARCHS[args.arch]
    guided = architecture in image_unet.GEOMETRY_GUIDED
    with_variance = architecture in image_unet.VARIANCE_GUIDED
    if args.loss_scale == "filter" and not with_variance:
        p.error(f"--loss-scale filter: {args.arch} has no a-trous filter to run (kpn3 or kpn4 does)")
    train = Dataset(args.data, need_depth=guided, need_variance=with_variance)
    val = Dataset([args.val], with_reference=True, need_depth=guided, need_variance=with_variance)
    if not train.keys:
        raise DataError(f"{', '.join(args.data)}: no complete views yet")
    if not val.keys:
        raise DataError(f"{args.val}: no view with a reference (make_denoise_data.py --validation)")
    overlap = train.scenes() & val.scenes()
    if overlap:
        raise DataError(f"{args.val}: interiors {sorted(overlap)} are also in the training data "
                        "(validation must be other interiors)")
    run.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)
    model = image_unet.ImageUNet(args.k, architecture)
    # Start as a mild blur: the direct variant's head at log1p(0.18), the exposure key, so the
    # first steps do not spend themselves lifting a dark output; each kernel's centre tap at
    # about 0.7 of its weight. Or from --init's weights.
    if args.init and not args.resume:
        try:
            if args.init.endswith(".osrw"):
                # A packed model (the shipped one): the same weights, read back from the file.
                from weights_pack import PackError, unpack_image_denoiser
                try:
                    start_from = unpack_image_denoiser(args.init)
                except PackError as e:
                    raise DataError(f"--init {e}") from None
            else:
                start_from = torch.load(args.init, map_location="cpu")
            start_arch = image_unet.architecture_of(start_from["model"], start_from.get("architecture"))
            kernels = image_unet.KERNEL_ARCHITECTURES
            if (start_arch in kernels) != (architecture in kernels):
                raise DataError(f"--init {args.init}: a {start_arch} model cannot start a {architecture} run")
            model.load_state_dict(start_from["model"])
            if architecture in image_unet.VARIANCE_GUIDED and start_arch not in image_unet.VARIANCE_GUIDED:
                # The other kernel models' logits make a blur of their own; v3's and v4's start
                # as the a-trous filter (their fixed factors), so the head starts near zero.
                with torch.no_grad():
                    model.dec0[-1].weight.mul_(0.1)
                    model.dec0[-1].bias.zero_()
        except DataError:
            raise
        except Exception as e:  # torch raises many kinds for a file that is not a checkpoint
            raise DataError(f"--init {args.init}: not an image denoiser checkpoint of K={args.k} "
                            f"({type(e).__name__})") from None
    else:
        with torch.no_grad():
            head = model.dec0[-1]
            head.weight.mul_(0.1)
            if args.arch == "unet":
                head.bias.fill_(math.log1p(image_unet.EXPOSURE_KEY))
            else:
                taps = image_unet.KERNEL_SIZE ** 2
                centre = 0.0 if architecture in image_unet.VARIANCE_GUIDED else 4.0  # v3, v4: the filter's
                head.bias.copy_(torch.tensor([centre if i % taps == taps // 2 else 0.0
                                              for i in range(image_unet.KPN_OUT_CHANNELS)]))
    model.to(args.device)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr)
    ema = image_unet.ImageUNet(args.k, architecture).to(args.device)
    ema.load_state_dict(model.state_dict())
    selection = f"{SELECT_METRIC} min_spp {args.min_spp}"
    state = {"step": 0, "crops": 0, "pixels": 0, "elapsed": 0.0, "best": math.inf, "select": selection}
    if args.resume:
        ck = torch.load(ckpt_path, map_location="cpu")
        if ck.get("base_width") != args.k or ck.get("architecture") != architecture:
            raise DataError(f"{ckpt_path}: {ck.get('architecture')} K={ck.get('base_width')} but "
                            f"--arch {args.arch} --k {args.k}")
        model.load_state_dict(ck["model"])
        opt.load_state_dict(ck["optimizer"])
        if "ema" in ck:
            ema.load_state_dict(ck["ema"])
        else:  # a checkpoint from before the average was kept
            ema.load_state_dict(ck["model"])
        state = ck["state"]
        if state.get("select") != selection:
            # best.pt was chosen by another figure (or at other sample counts): not comparable.
            state["best"] = math.inf
            state["select"] = selection
        print(f"train_denoiser.py: resuming {ckpt_path} at step {state['step']} "
              f"({state['elapsed'] / 60:.1f} min)", file=sys.stderr)
    meta = {"architecture": architecture, "stage": image_unet.STAGE, "base_width": args.k,
            "inputs": ",".join(image_unet.INPUTS), "input_transform": image_unet.INPUT_TRANSFORM,
            "loss_kind": ("relmse_exposed_n2n" if args.loss_scale == "output" else "relmse_filter_exposed_n2n")
            + (f"_huber{args.loss_cap:g}" if args.loss_cap else ""),
            "datasets": ",".join(Path(d).name for d in args.data),
            "init": Path(args.init).parent.name + "/" + Path(args.init).name if args.init else "",
            "validation": Path(args.val).name,
            "batch": args.batch, "crop": args.crop, "lr": args.lr, "min_spp": args.min_spp, "git_commit": git_commit(),
            "quick": bool(args.quick)}
    print(f"train_denoiser.py: {len(train.keys)} views ({train.pixels() / 1e6:.1f} Mpixel) from "
          f"{len(train.scenes())} interiors, validation {len(val.keys)} views; K={args.k}", file=sys.stderr)
    rng = np.random.default_rng(args.seed * 1000003 + state["step"])
    budget = args.minutes * 60.0
    start = time.monotonic() - state["elapsed"]
    last_ckpt = last_eval = last_reload = time.monotonic()
    window_t, window_n, running = time.monotonic(), 0, None
    val_err = None
    model.train()

    def epoch() -> float:
        return state["pixels"] / max(train.pixels(), 1)

    def checkpoint() -> None:
        state["elapsed"] = time.monotonic() - start
        save_atomic({"model": model.state_dict(), "ema": ema.state_dict(), "optimizer": opt.state_dict(),
                     "state": state,
                     "base_width": args.k, "architecture": architecture}, ckpt_path)

    def validate() -> dict:
        """Validates the moving average, logs it, keeps it as best.pt when best; returns it as
        best.pt holds it (weights and metadata)."""
        nonlocal val_err
        errors = evaluate(ema, val, args.min_spp)
        val_err = errors["val_select"]
        elapsed = time.monotonic() - start
        entry = {"step": state["step"], "crops": state["crops"], "epoch": round(epoch(), 3),
                 "train_loss": running, **errors, "minutes": round(elapsed / 60, 2),
                 "crops_per_s": round(state["crops"] / max(elapsed, 1e-9), 2), "train_views": len(train.keys)}
        with open(log_path, "a") as f:
            f.write(json.dumps(entry) + "\n")
        weights = {"model": ema.state_dict(), **meta, "epoch": entry["epoch"], "step": state["step"],
                   "loss": running if running is not None else float("nan"), **errors,
                   "train_views": len(train.keys), "train_interiors": len(train.scenes()),
                   "val_views": len(val.keys), "val_ref_spp": min(v.ref_spp for v in val.views.values()),
                   "train_minutes": entry["minutes"]}
        if val_err < state["best"]:
            state["best"] = val_err
            save_atomic(weights, best_path)
        return weights

    def done_fraction() -> float:
        if args.steps:
            return state["step"] / args.steps
        return (time.monotonic() - start) / budget

    if args.init and state["step"] == 0:
        validate()  # the starting weights are a candidate too
    while True:
        elapsed = time.monotonic() - start
        frac = done_fraction()
        if frac >= 1.0:
            break
        for group in opt.param_groups:  # cosine decay over the budget
            group["lr"] = args.lr * 0.5 * (1 + math.cos(math.pi * frac))
        colour, albedo, normal, depth, variance, e, target, _, light = make_batch(
            train, rng, args.batch, args.crop, args.device, args.min_spp)
        loss = loss_fn(model, colour, albedo, normal, depth, variance, e, target, args.loss_scale, light,
                       args.loss_cap)
        opt.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        with torch.no_grad():
            for a, b in zip(ema.parameters(), model.parameters()):
                a.lerp_(b, 1.0 - args.ema)
        state["step"] += 1
        state["crops"] += args.batch
        state["pixels"] += colour.shape[0] * colour.shape[2] * colour.shape[3]
        window_n += args.batch
        running = float(loss) if running is None else 0.98 * running + 0.02 * float(loss)
        now = time.monotonic()
        if now - last_reload >= args.reload_s:
            added = train.reload()
            if added:
                print(f"\ntrain_denoiser.py: {added} newly rendered views, {len(train.keys)} in all",
                      file=sys.stderr)
            last_reload = time.monotonic()
        if now - last_eval >= args.eval_s:
            validate()
            last_eval = time.monotonic()
        if now - last_ckpt >= args.checkpoint_s:
            checkpoint()
            last_ckpt = time.monotonic()
        if state["step"] % 5 == 0:
            rate = window_n / max(now - window_t, 1e-9)
            if now - window_t > 30:
                window_t, window_n = now, 0
            left = elapsed * (1 - frac) / max(frac, 1e-9)
            sys.stderr.write(progress_line(frac, state["step"], epoch(), running, rate, val_err, left))
            sys.stderr.flush()
    final = validate()
    checkpoint()
    save_atomic(final, final_path)
    sys.stderr.write("\n")
    print(f"train_denoiser.py: {state['step']} steps ({epoch():.1f} epochs) in "
          f"{(time.monotonic() - start) / 60:.1f} min", file=sys.stderr)
    return evaluate_checkpoint(str(best_path), args.val, run)
    return 0


def evaluate_checkpoint(path: str, val_folder: str, run: Path, record_path: str | None = None) -> int:
    """Validates the checkpoint at path on every referenced view of val_folder (references as
    they are now), prints relMSE per input spp beside the noisy input's, writes run/eval.json
    and, with record_path, the checkpoint's scalar metadata with these figures there."""
    import torch
    import image_unet
    try:
        ck = torch.load(path, map_location="cpu")
        model = image_unet.ImageUNet(image_unet.base_width(ck["model"]),
                                     image_unet.architecture_of(ck["model"], ck.get("architecture")))
        model.load_state_dict(ck["model"])
    except Exception as e:  # torch raises many kinds for a file that is not a checkpoint
        raise DataError(f"{path}: not an image denoiser checkpoint ({type(e).__name__})") from None
    val = Dataset([val_folder], with_reference=True,
                  need_depth=model.architecture in image_unet.GEOMETRY_GUIDED,
                  need_variance=model.architecture in image_unet.VARIANCE_GUIDED)
    if not val.keys:
        raise DataError(f"{val_folder}: no view with a reference (make_denoise_data.py --validation)")
    final = evaluate(model, val)
    run.mkdir(parents=True, exist_ok=True)
    record = {"checkpoint": path, "step": ck.get("step"), "val_views": len(val.keys),
              "val_ref_spp": min(v.ref_spp for v in val.views.values()), **final}
    (run / "eval.json").write_text(json.dumps(record, indent=1) + "\n")
    if record_path:
        meta = {k: v for k, v in ck.items() if isinstance(v, (int, float, str, bool)) and not k.startswith("val_")}
        Path(record_path).write_text(json.dumps({**meta, "evaluation": {k: v for k, v in record.items()
                                                                        if k != "checkpoint"}},
                                                indent=1) + "\n")
    for key in sorted((k for k in final if k.startswith("val_relmse_") and k.endswith("spp")),
                      key=lambda k: int(k[len("val_relmse_"):-3])):
        spp = key[len("val_relmse_"):-3]
        against = (f", a-trous filter {final[f'val_filter_relmse_{spp}spp']:.5f}"
                   if f"val_filter_relmse_{spp}spp" in final else "")
        print(f"train_denoiser.py: {spp} spp: relMSE {final[key]:.5f} (noisy input "
              f"{final[f'val_noisy_relmse_{spp}spp']:.5f}{against}), {len(val.keys)} views, reference "
              f"{record['val_ref_spp']} spp", file=sys.stderr)
    print(f"train_denoiser.py: the reference's own noise adds about {final['val_reference_noise']:.5f} "
          "to each figure", file=sys.stderr)
    return 0


def run_main(argv: list[str] | None = None) -> int:
    """main() with the user's mistakes as one line and exit code 2."""
    try:
        return main(argv)
    except DataError as e:
        print(f"train_denoiser.py: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(run_main())
