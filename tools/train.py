#!/usr/bin/python3
"""Trains osr-vk's U-Net (tools/unet.py) on hemisphere maps and exports packed weights.

usage: train.py DATA [DATA ...] --val VAL --out RUN [--k 16] [--minutes 30 | --steps N] [--batch 64]
                [--lr 1e-3] [--loss relmse|l1log] [--threads 2] [--seed 1]
       torchrun --nproc_per_node N [--nnodes M ...] train.py ...   (data-parallel, docs/farm.md)

DATA and VAL are make_dataset.py folders (docs/training.md); VAL holds scenes that DATA does
not (a split by scene). The run folder RUN gets:
- checkpoint.pt: model, optimizer, step, examples, elapsed time, written atomically every
  --checkpoint-s seconds; a run started again with the same RUN resumes from it;
- best.pt: the weights with the lowest validation error, with the training metadata;
- train.log: one JSON object per evaluation (step, examples, epoch, losses, examples/s);
- model.osrw: best.pt packed by weights_pack.py when the budget is spent.

Training: maps normalized as tools/maps_data.py says (DESIGN.md "Normalization", the target
scaled by the one-shot map's mean); each batch turned by a random one of the 8 symmetries
of the square, normals included; Adam with a cosine learning-rate decay over the time budget.
Loss (--loss):
- relmse (default): ((f - t)^2 / (sg(f) + 0.01)^2), f = exp(y) - 1 and t the target in linear
  units of 10 m, sg = no gradient (Lehtinen et al. 2018's HDR loss). It is mean-seeking, so a
  noisy target (Noise2Noise) trains towards its expectation, and relative, so dark and bright
  texels count alike;
- l1log: |y - log(1 + t)|, the seed's L1 on log-normalized maps (median-seeking: biased with
  noisy targets).
Data-parallel under torchrun (WORLD_SIZE > 1): gloo on CPU, NCCL where GPUs are. Every process
draws the same batch of --batch rows and trains on its share (--batch / processes; --batch must
divide), gradients are averaged (DistributedDataParallel), so the run is one process's with the
same total batch, up to BatchNorm statistics taken per share; process 0 alone validates, writes
the run folder and decides when the budget is spent.
Validation error: relMSE (epsilon 0.01) against VAL's reference, on maps scaled to the
reference's unit mean, of the network's map rescaled to the one-shot channel means
(val_relmse_rescaled, the renderer's default; it picks best.pt unless --select absolute) and
as predicted (val_relmse).
"""
from __future__ import annotations

import argparse
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
import maps_data  # noqa: E402
from arg_types import positive_float, positive_int, seed_int  # noqa: E402


def git_commit() -> str:
    try:
        return subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def seeds_text(seeds: set[int]) -> str:
    """1,2,3,5 -> '1-3,5'."""
    out, run = [], []
    for s in sorted(seeds):
        if run and s != run[-1] + 1:
            out.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
            run = []
        run.append(s)
    if run:
        out.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
    return ",".join(out)


class Data:
    """A dataset in memory, normalized once: network input, target in linear units of 10 m."""

    def __init__(self, folders: list[str]) -> None:
        shards = maps_data.Shards(folders)
        x, y = shards.load_all()
        keep = maps_data.usable(x, y)
        self.raw_x, self.raw_y = x[keep], y[keep]
        self.x = maps_data.normalize_input(self.raw_x)
        self.t = self.raw_y / maps_data.target_scale(self.raw_x)
        self.count = len(self.x)
        self.dropped = int((~keep).sum())
        self.scenes = shards.scenes
        self.spp = shards.spp


def loss_fn(kind: str, y, t):
    import torch
    if kind == "l1log":
        return (y - torch.log1p(t)).abs().mean()
    f = torch.expm1(y)
    return ((f - t) ** 2 / (f.detach() + 0.01) ** 2).mean()


def evaluate(model, val: Data, batch: int, loss_kind: str) -> dict:
    """Mean loss and mean map relMSE against the reference on the whole set, of the network's
    map as it predicts it (absolute: 10 m (exp(y) - 1)) and rescaled to the one-shot map's
    channel means (the seed's denormalization)."""
    import torch
    model.eval()
    losses, absolute, rescaled = [], [], []
    with torch.no_grad():
        for i in range(0, val.count, batch):
            xb = torch.from_numpy(val.x[i:i + batch])
            tb = torch.from_numpy(val.t[i:i + batch])
            y = model(xb)
            losses.append(float(loss_fn(loss_kind, y, tb)) * len(xb))
            raw_x, ref = val.raw_x[i:i + batch], val.raw_y[i:i + batch]
            pred = np.expm1(y.numpy()) * maps_data.target_scale(raw_x)
            absolute.append(maps_data.map_relmse(pred, ref))
            rescaled.append(maps_data.map_relmse(maps_data.rescale_to_input(pred, raw_x), ref))
    model.train()
    return {"val_loss": sum(losses) / val.count, "val_relmse": float(np.concatenate(absolute).mean()),
            "val_relmse_rescaled": float(np.concatenate(rescaled).mean())}


def save_atomic(obj, path: Path) -> None:
    import torch
    tmp = path.with_name(path.name + ".tmp")
    torch.save(obj, tmp)
    os.replace(tmp, path)


def progress_line(frac: float, step: int, epoch: float, loss: float, rate: float, val: float | None,
                  remaining: float) -> str:
    bar = "#" * int(frac * 24) + "-" * (24 - int(frac * 24))
    v = f" val {val:.4f}" if val is not None else ""
    return (f"\r[{bar}] {100 * frac:5.1f}% step {step} epoch {epoch:.2f} loss {loss:.4f}{v} "
            f"{rate:.1f} ex/s, {int(remaining // 60)}:{int(remaining % 60):02d} left ")


def init_distributed(torch) -> tuple[int, int]:
    """(rank, processes) of a torchrun job, its process group made; (0, 1) outside torchrun."""
    world = int(os.environ.get("WORLD_SIZE", "1"))
    if world == 1:
        return 0, 1
    import torch.distributed as dist
    dist.init_process_group("nccl" if torch.cuda.is_available() else "gloo")
    return dist.get_rank(), world


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command line, every value checked (argparse's one-line error and exit 2 otherwise)."""
    p = argparse.ArgumentParser(prog="train.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("data", nargs="+", help="training dataset folders (make_dataset.py)")
    p.add_argument("--val", required=True, help="validation dataset folder (other scenes)")
    p.add_argument("--out", required=True, help="run folder (resumed if it holds checkpoint.pt)")
    p.add_argument("--k", type=positive_int, default=16, help="base width K of the U-Net (default 16)")
    p.add_argument("--minutes", type=positive_float, default=30.0, help="training time budget (default 30)")
    p.add_argument("--steps", type=positive_int, help="a budget in steps instead of time (comparisons on a busy machine)")
    p.add_argument("--batch", type=positive_int, default=64, help="batch size (default 64)")
    p.add_argument("--lr", type=positive_float, default=1e-3, help="initial Adam learning rate (default 1e-3)")
    p.add_argument("--loss", choices=["relmse", "l1log"], default="relmse", help="loss (default relmse)")
    p.add_argument("--threads", type=positive_int, default=2, help="PyTorch CPU threads (default 2)")
    p.add_argument("--seed", type=seed_int, default=1, help="seed of initialization and batches (default 1)")
    p.add_argument("--eval-s", type=positive_float, default=120.0, help="seconds between validations (default 120)")
    p.add_argument("--checkpoint-s", type=positive_float, default=60.0, help="seconds between checkpoints (default 60)")
    p.add_argument("--select", choices=["rescaled", "absolute"], default="rescaled",
                   help="which validation error picks best.pt: of the map rescaled to the one-shot "
                   "means (the shipped normalization, default) or as predicted")
    p.add_argument("--init", help="start from this checkpoint's weights (best.pt or checkpoint.pt of the same K)")
    p.add_argument("--no-export", action="store_true", help="do not pack model.osrw at the end")
    return p.parse_args(argv)


def load_data(folders: list[str], val_folder: str) -> tuple[Data, Data]:
    """The training and validation sets, checked: each a make_dataset.py folder, no scene in
    both (validation is split by scene), usable maps in each. DataError naming the problem."""
    for folder in [*folders, val_folder]:
        if not (Path(folder) / "dataset.json").is_file():
            raise maps_data.DataError(f"{folder}: no dataset.json (not a make_dataset.py folder)")
    train, val = Data(folders), Data([val_folder])
    if train.scenes & val.scenes:
        raise maps_data.DataError(f"{val_folder}: scenes {seeds_text(train.scenes & val.scenes)} are also in "
                                  "the training data (validation must be split by scene)")
    if train.count == 0 or val.count == 0:
        raise maps_data.DataError("no usable maps in the training or validation data")
    return train, val


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    import torch
    from unet import UNet
    torch.set_num_threads(args.threads)
    rank, world = init_distributed(torch)
    if args.batch % world:
        print(f"train.py: --batch {args.batch} does not divide among {world} processes", file=sys.stderr)
        return 2
    lead = rank == 0  # the process that validates, writes the run folder and prints
    train, val = load_data(args.data, args.val)
    run = Path(args.out)
    if lead:
        run.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)
    model = UNet(args.k)
    # Start the output near the targets' level (log(1 + 0.1), a texel at the map's mean): the
    # final ReLU passes no gradient to a texel it clamps, so a default-initialized head that
    # clamps half the texels to 0 learns them late.
    with torch.no_grad():
        head = model.decoder2[-2]
        head.weight.mul_(0.1)
        head.bias.fill_(0.1)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr)
    net = model
    if world > 1:
        import torch.distributed as dist
        from torch.nn.parallel import DistributedDataParallel
        net = DistributedDataParallel(model)  # broadcasts rank 0's weights, averages gradients
    state = {"step": 0, "examples": 0, "elapsed": 0.0, "best": math.inf, "rng": args.seed}
    ckpt_path, best_path, log_path = run / "checkpoint.pt", run / "best.pt", run / "train.log"
    if args.init and not ckpt_path.is_file():
        load_weights(model, args.init)
        if lead:
            print(f"train.py: starting from the weights of {args.init}", file=sys.stderr)
    if ckpt_path.is_file():
        ck = torch.load(ckpt_path, map_location="cpu")
        if ck["k"] != args.k:
            print(f"train.py: {ckpt_path}: K={ck['k']} but --k {args.k}", file=sys.stderr)
            return 2
        model.load_state_dict(ck["model"])
        opt.load_state_dict(ck["optimizer"])
        state = ck["state"]
        if lead:
            print(f"train.py: resuming {ckpt_path} at step {state['step']} ({state['elapsed'] / 60:.1f} min)",
                  file=sys.stderr)
    meta = {"k": args.k, "loss": args.loss, "datasets": ",".join(args.data), "validation": args.val,
            "train_scenes": seeds_text(train.scenes), "val_scenes": seeds_text(val.scenes),
            "target_spp": ",".join(str(s) for s in sorted(train.spp)), "train_maps": train.count,
            "val_maps": val.count, "batch": args.batch, "lr": args.lr, "git_commit": git_commit(),
            "init": args.init or "", "processes": world}
    # The header's normalization tells the renderer how to turn the output into radiance.
    from weights_pack import read_format
    fmt = read_format()
    meta["normalization"] = fmt["kNormalizationLogMean10Absolute" if args.select == "absolute"
                                else "kNormalizationLogMean10"]
    if lead:
        print(f"train.py: {train.count} maps from {len(train.scenes)} scenes ({train.dropped} dropped: unlit or off by 100x), "
              f"validation {val.count} maps from {len(val.scenes)} scenes; K={args.k}, loss {args.loss}"
              + (f"; {world} processes of {args.batch // world} maps a batch" if world > 1 else ""), file=sys.stderr)
    rng = np.random.default_rng(state["rng"] * 1000003 + state["step"])
    budget = args.minutes * 60.0
    start = time.monotonic() - state["elapsed"]
    last_ckpt = last_eval = time.monotonic()
    window_t, window_n, running = time.monotonic(), 0, None
    val_err = None
    model.train()

    def checkpoint() -> None:
        state["elapsed"] = time.monotonic() - start
        save_atomic({"model": model.state_dict(), "optimizer": opt.state_dict(), "state": state, "k": args.k},
                    ckpt_path)

    def validate() -> None:
        nonlocal val_err
        errors = evaluate(model, val, 256, args.loss)
        val_err = errors["val_relmse_" + args.select] if args.select == "rescaled" else errors["val_relmse"]
        elapsed = time.monotonic() - start
        entry = {"step": state["step"], "examples": state["examples"],
                 "epoch": round(state["examples"] / train.count, 3), "train_loss": running, **errors,
                 "minutes": round(elapsed / 60, 2),
                 "examples_per_s": round(state["examples"] / max(elapsed, 1e-9), 1)}
        with open(log_path, "a") as f:
            f.write(json.dumps(entry) + "\n")
        if val_err < state["best"]:
            state["best"] = val_err
            save_atomic({"state_dict": model.state_dict(), **meta, "step": state["step"],
                         "examples": state["examples"], "epochs": entry["epoch"], **errors,
                         "train_minutes": entry["minutes"]}, best_path)

    def done_fraction() -> float:
        if args.steps:
            return state["step"] / args.steps
        return (time.monotonic() - start) / budget

    while True:
        elapsed = time.monotonic() - start
        frac = done_fraction()
        if world > 1:  # process 0's clock decides, so that every process stops at the same step
            t = torch.tensor([frac], dtype=torch.float64)
            dist.broadcast(t, 0)
            frac = float(t)
        if frac >= 1.0:
            break
        for group in opt.param_groups:  # cosine decay over the budget
            group["lr"] = args.lr * 0.5 * (1 + math.cos(math.pi * frac))
        rows = rng.integers(0, train.count, args.batch)[rank::world]  # this process's share
        sym = int(rng.integers(0, 8))
        xb = torch.from_numpy(maps_data.symmetry(train.x[rows], sym, normals=True))
        tb = torch.from_numpy(maps_data.symmetry(train.t[rows], sym, normals=False))
        loss = loss_fn(args.loss, net(xb), tb)
        opt.zero_grad()
        loss.backward()
        # A map of rare bright paths still makes a large relative loss now and then.
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        state["step"] += 1
        state["examples"] += args.batch
        window_n += args.batch
        running = float(loss) if running is None else 0.98 * running + 0.02 * float(loss)
        now = time.monotonic()
        if lead and now - last_eval >= args.eval_s:
            validate()
            last_eval = time.monotonic()
        if lead and now - last_ckpt >= args.checkpoint_s:
            checkpoint()
            last_ckpt = time.monotonic()
        if lead and state["step"] % 10 == 0:
            rate = window_n / max(now - window_t, 1e-9)
            if now - window_t > 30:
                window_t, window_n = now, 0
            left = elapsed * (1 - frac) / max(frac, 1e-9)
            sys.stderr.write(progress_line(frac, state["step"], state["examples"] / train.count, running, rate,
                                           val_err, left))
            sys.stderr.flush()
    if world > 1:
        dist.destroy_process_group()
    if not lead:
        return 0
    validate()
    checkpoint()
    sys.stderr.write("\n")
    print(f"train.py: {state['step']} steps, {state['examples']} examples "
          f"({state['examples'] / train.count:.1f} epochs) in {(time.monotonic() - start) / 60:.1f} min; "
          f"best validation relMSE {state['best']:.5f}", file=sys.stderr)
    if not args.no_export:
        import weights_pack
        rc = weights_pack.main([str(best_path), str(run / "model.osrw")])
        if rc != 0:
            return rc
        print(f"train.py: wrote {run / 'model.osrw'}", file=sys.stderr)
    return 0


def run(argv: list[str] | None = None) -> int:
    """main() with the user's mistakes as one line and exit code 2."""
    try:
        return main(argv)
    except maps_data.DataError as e:
        print(f"train.py: {e}", file=sys.stderr)
        return 2
    except CheckpointError as e:
        print(f"train.py: {e}", file=sys.stderr)
        return 2


class CheckpointError(Exception):
    """A checkpoint that is not this U-Net's (another architecture or K)."""


def load_weights(model, path: str) -> None:
    """The checkpoint at path (read as weights_pack.py reads one) into model; CheckpointError
    naming the file otherwise."""
    from weights_pack import PackError, load_state_dict
    try:
        model.load_state_dict(load_state_dict(path))
    except PackError as e:
        raise CheckpointError(str(e)) from None
    except RuntimeError as e:  # missing keys or shapes of another K
        raise CheckpointError(f"{path}: not a U-Net K={model.k} checkpoint ({str(e).splitlines()[0]})") from None


if __name__ == "__main__":
    sys.exit(run())
