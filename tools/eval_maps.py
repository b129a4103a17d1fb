#!/usr/bin/python3
"""Error of cleaned hemisphere maps on held-out scenes, as a table and a picture grid.

usage: eval_maps.py VAL --weights RUN/best.pt [--weights ...] [--target VAL16] --out DIR

VAL is a make_dataset.py folder whose targets are high-sample references (e.g. 128 paths per
texel) of scenes no model was trained on. For every map it compares against the reference:
- input: the one-shot map (1 path per texel), as traced;
- blur: the renderer's blur denoiser (5 x 5 Gaussian, sigma 1 texel, then each channel
  rescaled to the one-shot channel mean, as osr_map_denoise.comp);
- each model, as predicted (`NAME`: radiance 10 m (exp(y) - 1), m the one-shot mean) and
  rescaled to the one-shot channel means (`NAME rescaled`, the seed's denormalization);
- target: with --target, a make_dataset.py folder of the same scenes, seeds and grid with
  fewer paths per texel (the training targets' kind): the same points, so its error is the
  training target's own noise (its paths are the first of the reference's, so the figure is
  (1 - spp/reference_spp) of the noise against the truth; the table says so).
Metrics, on each map scaled to the reference's unit mean and then averaged over maps:
- L1 and relMSE (epsilon 0.01) of radiance per texel;
- irradiance (pi x the texel mean per channel, the Lambertian integral): relative L1 and
  relMSE (squared relative error).
Writes DIR/eval.json, DIR/eval.md (the table) and DIR/grid.png: one row per sampled map,
columns input, blur, each model (rescaled), target, reference (tone mapped by the reference's
mean); DIR/grid.txt names the columns.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import maps_data  # noqa: E402
from arg_types import positive_int  # noqa: E402
from gltf_build import png  # noqa: E402

GAUSS = np.array([0.05448, 0.24420, 0.40262, 0.24420, 0.05448])


def blur(x: np.ndarray) -> np.ndarray:
    """The renderer's blur denoiser on the one-shot radiance, edge taps renormalized."""
    r = np.maximum(x[:, 0:3], 0)
    w = np.ones((1, 1, 32, 32))
    for axis in (2, 3):
        pad = [(0, 0)] * 4
        pad[axis] = (2, 2)
        rp, wp = np.pad(r, pad), np.pad(w, pad)
        r = sum(GAUSS[k] * np.take(rp, range(k, k + 32), axis=axis) for k in range(5))
        w = sum(GAUSS[k] * np.take(wp, range(k, k + 32), axis=axis) for k in range(5))
    return maps_data.rescale_to_input(r / w, x)


def metrics(pred: np.ndarray, ref: np.ndarray) -> dict:
    m = np.maximum(ref.mean(axis=(1, 2, 3), keepdims=True), 1e-30)
    p, r = pred / m, ref / m
    ep, er = p.mean(axis=(2, 3)), r.mean(axis=(2, 3))  # irradiance / pi, per channel
    rel = (ep - er) / np.maximum(er, 1e-6)
    return {"l1": float(np.abs(p - r).mean()), "relmse": float(maps_data.map_relmse(pred, ref).mean()),
            "irradiance_l1": float(np.abs(rel).mean()), "irradiance_relmse": float((rel ** 2).mean())}


def predict(path: str, x: np.ndarray) -> tuple[str, np.ndarray]:
    import torch
    from unet import UNet, base_width
    from weights_pack import PackError, load_state_dict
    try:
        state = load_state_dict(path)  # best.pt, checkpoint.pt or a state_dict
        model = UNet(base_width(state))
        model.load_state_dict(state)
    except PackError as e:
        raise maps_data.DataError(str(e)) from None
    except (ValueError, RuntimeError) as e:  # not this architecture's keys or shapes
        raise maps_data.DataError(f"{path}: not a U-Net checkpoint ({str(e).splitlines()[0]})") from None
    model.eval()
    xn = maps_data.normalize_input(x)
    out = []
    with torch.no_grad():
        for i in range(0, len(x), 128):
            out.append(np.expm1(model(torch.from_numpy(xn[i:i + 128])).numpy()))
    name = f"U-Net K={base_width(state)} ({Path(path).parent.name}/{Path(path).stem})"
    return name, np.concatenate(out) * maps_data.target_scale(x)


def tonemap(a: np.ndarray, mean: float) -> np.ndarray:
    """[3,32,32] radiance -> [96,96,3] uint8: scaled by the reference mean, x/(1+x), gamma 2.2,
    each texel 3 x 3 pixels."""
    v = np.maximum(a, 0) / max(mean, 1e-30) * 0.5
    v = (v / (1 + v)) ** (1 / 2.2)
    img = (np.clip(v, 0, 1) * 255 + 0.5).astype(np.uint8).transpose(1, 2, 0)
    return img.repeat(3, axis=0).repeat(3, axis=1)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="eval_maps.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("val", help="make_dataset.py folder with high-sample reference targets")
    p.add_argument("--weights", action="append", default=[], help="a train.py checkpoint (best.pt); repeatable")
    p.add_argument("--target", help="same scenes and points with training-kind targets (fewer paths)")
    p.add_argument("--out", required=True, help="folder for eval.json, eval.md and grid.png")
    p.add_argument("--rows", type=positive_int, default=6, help="maps in the picture grid (default 6)")
    args = p.parse_args(argv)
    for folder in [args.val] + ([args.target] if args.target else []):
        if not (Path(folder) / "dataset.json").is_file():
            print(f"eval_maps.py: {folder}: no dataset.json (not a make_dataset.py folder)", file=sys.stderr)
            return 2
    shards = maps_data.Shards([args.val])
    x, ref = shards.load_all()
    keep = maps_data.usable(x, ref)
    ref_spp = max(shards.spp)
    methods: dict[str, np.ndarray] = {"input (1 path/texel)": np.maximum(x[:, 0:3], 0), "blur": blur(x)}
    for w in args.weights:
        name, pred = predict(w, x)
        methods[name] = pred
        methods[name + " rescaled"] = maps_data.rescale_to_input(pred, x)
    target_spp = None
    if args.target:
        tshards = maps_data.Shards([args.target])
        tx, target = tshards.load_all()
        if tx.shape != x.shape or not np.array_equal(tx, x):
            print(f"eval_maps.py: {args.target}: not the same points and inputs as {args.val}", file=sys.stderr)
            return 2
        target_spp = max(tshards.spp)
        methods[f"target ({target_spp} paths/texel)"] = target
    rows = []
    for name, pred in methods.items():
        rows.append({"method": name, **metrics(pred[keep], ref[keep])})
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    result = {"val": args.val, "maps": int(keep.sum()), "scenes": sorted(shards.scenes),
              "reference_spp": ref_spp, "target_spp": target_spp, "weights": args.weights, "rows": rows}
    (out / "eval.json").write_text(json.dumps(result, indent=1) + "\n")
    lines = [f"Held-out scenes {sorted(shards.scenes)}, {int(keep.sum())} maps, reference {ref_spp} paths/texel; "
             "errors on maps scaled to the reference's unit mean.", "",
             "| method | L1 | relMSE | irradiance rel. L1 | irradiance relMSE |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['method']} | {r['l1']:.4f} | {r['relmse']:.4f} | {r['irradiance_l1']:.4f} | "
                     f"{r['irradiance_relmse']:.4f} |")
    if target_spp:
        lines += ["", f"The target's paths are the first {target_spp} of the reference's {ref_spp}: its "
                  f"figures are {1 - target_spp / ref_spp:.3f} of its noise against the truth."]
    (out / "eval.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    # Picture grid: maps spread over the set, columns = methods + reference; each model as the
    # renderer uses it by default (rescaled to the one-shot channel means).
    picked = np.flatnonzero(keep)[np.linspace(0, keep.sum() - 1, args.rows).astype(int)]
    columns = [n for n in methods if not n.startswith("U-Net") or n.endswith("rescaled")]
    tiles = []
    for i in picked:
        mean = float(ref[i].mean())
        tiles.append(np.concatenate([tonemap(methods[n][i], mean) for n in columns] + [tonemap(ref[i], mean)], axis=1))
    grid = np.concatenate(tiles, axis=0)
    texels = [(int(c[0]), int(c[1]), int(c[2]), 255) for c in grid.reshape(-1, 3)]
    (out / "grid.png").write_bytes(png(grid.shape[1], grid.shape[0], texels))
    (out / "grid.txt").write_text("columns: " + ", ".join(columns + ["reference"]) + "\n")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except maps_data.DataError as e:
        print(f"eval_maps.py: {e}", file=sys.stderr)
        sys.exit(2)
