#!/usr/bin/python3
"""Runs an osr-vk job as tasks on a Dask distributed cluster: the frames of a shot, the tiles
of one large image, or the shards of a training set (docs/farm.md).

usage: osr_farm.py frames A-B    [CLUSTER] [OPTIONS] -- OSR_VK_ARGS...
       osr_farm.py tiles RxC     [CLUSTER] [OPTIONS] -- OSR_VK_ARGS...
       osr_farm.py dataset SEEDS [CLUSTER] [OPTIONS] -- OUT [make_dataset.py options]
CLUSTER: --workers N (a LocalCluster on this machine, the default, N = 2), --scheduler
tcp://HOST:PORT or --scheduler-file F (a running cluster; workers see the same paths).

OSR_VK_ARGS are those of one whole render (--offline OUT.exr, --png, the scene, the mode and
its budget). frames A-B: frame N is osr-vk --frames N-N of an animated glTF (its time N / fps),
else the scene's glTF camera N (--camera N), written to OUT.NNNN.exr (or the name's run of #
filled in, and PNG likewise), one osr-vk process per frame. tiles RxC: R rows by C columns
of the image, each rendered with osr-vk --crop (the full image's samples) plus a margin that
OSR's maps need (--margin, default 2 x --grid-start, 0 for path and preview) and assembled into
OUT.exr with every layer: path mode equals a single render bit for bit. dataset SEEDS: one
task per scene seed, tools/make_dataset.py OUT/shards/SEED, merged into OUT/dataset.json.

Faults: a task whose worker dies is run again elsewhere (Dask); outputs are written under a
temporary name and renamed; a rerun skips outputs that are complete (EXR header and chunk table
read, not only the name); a task that fails twice the same way stops the job with one line.
Before submitting, every worker's `osr-vk --version` must match and see the input files.
Progress on stderr (tasks done, failed, retried); a JSON summary on stdout at the end.
Bad input: one line, exit 2, nothing written.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import exr_file  # noqa: E402
from arg_types import parse_seeds, positive_int  # noqa: E402

PROG = "osr_farm.py"
MIN_TILE = 16  # pixels: a smaller tile is all margin and process start
RENDER_OPTIONS_WITH_VALUE = {
    "--offline", "--png", "--mode", "--spp", "--passes", "--time", "--seed", "--exposure", "--width",
    "--height", "--camera", "--env", "--device", "--denoiser", "--weights", "--grid-start", "--grid-min",
    "--map-share", "--direct-spp", "--residual-spp", "--residual-ramp", "--map-spp", "--dump-maps", "--crop",
    "--viewer-script", "--save-dir", "--frames", "--fps"}


class BadInput(Exception):
    """One line for stderr, exit 2."""


class JobFailed(Exception):
    """One line for stderr, exit 1."""


# ---- What runs on the workers (pickled by value with this module's __main__) --------------

def worker_version(osr_vk: str) -> str:
    try:
        r = subprocess.run([osr_vk, "--version"], capture_output=True, text=True, timeout=60)
    except OSError as e:
        return f"cannot run {osr_vk} ({e.strerror})"
    return r.stdout.strip() if r.returncode == 0 else f"{osr_vk} --version exit {r.returncode}"


def worker_missing(paths: list[str]) -> list[str]:
    return [p for p in paths if not os.path.isfile(p)]


def _die_with_parent() -> None:
    # A worker killed (SIGKILL) takes its osr-vk along instead of leaving it rendering a task
    # that is already running again elsewhere.
    import ctypes
    import signal
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def run_task(name: str, cmd: list[str], done_marker: str | None = None) -> dict:
    """Runs one task's command; returns its timings or raises RuntimeError(first error line)."""
    import socket
    start = time.time()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       preexec_fn=_die_with_parent)
    wall = time.time() - start
    if r.returncode != 0:
        raise RuntimeError(first_error_line(r.stderr) or f"exit code {r.returncode}")
    if done_marker:
        tmp = done_marker + ".tmp"
        Path(tmp).write_text(json.dumps({"task": name, "seconds": round(wall, 3)}) + "\n")
        os.replace(tmp, done_marker)
    render = re.findall(r"^osr-vk: \d+x\d+, \d+ \S+ in ([0-9.]+) s", r.stderr, re.M)
    return {"task": name, "worker": socket.gethostname(), "pid": os.getpid(), "start": start,
            "wall_s": round(wall, 3), "render_s": float(render[-1]) if render else None}


def first_error_line(stderr: str) -> str:
    """osr-vk's first line that is not progress or a warning (the error it exits with)."""
    for line in stderr.splitlines():
        line = line.strip("\r ").split("\r")[-1].strip()
        if not line or re.match(r"osr-vk: \d+(/\d+)? \w+[ ,(]", line) or "warning:" in line:
            continue
        return line
    return ""


# ---- The client -----------------------------------------------------------------------------

def option_value(args: list[str], name: str) -> str | None:
    for i, a in enumerate(args):
        if a == name and i + 1 < len(args):
            return args[i + 1]
        if a.startswith(name + "="):
            return a[len(name) + 1:]
    return None


def replace_option(args: list[str], name: str, value: str | None) -> list[str]:
    """args without `name` and its value; then `name value` appended unless value is None."""
    out, skip = [], False
    for i, a in enumerate(args):
        if skip:
            skip = False
            continue
        if a == name:
            skip = True
            continue
        if a.startswith(name + "="):
            continue
        out.append(a)
    return out + ([name, value] if value is not None else [])


def positional(args: list[str]) -> list[str]:
    out, skip = [], False
    for a in args:
        if skip:
            skip = False
        elif a in RENDER_OPTIONS_WITH_VALUE:
            skip = True
        elif not a.startswith("-"):
            out.append(a)
    return out


def absolute_paths(args: list[str]) -> list[str]:
    """Paths made absolute, so that workers with another working folder find them."""
    out, prev = [], None
    for a in args:
        if prev in ("--offline", "--png", "--env", "--weights", "--dump-maps") and not (prev == "--env" and a == "none"):
            a = str(Path(a).resolve())
        elif prev not in RENDER_OPTIONS_WITH_VALUE and not a.startswith("-") and Path(a).suffix in (".gltf", ".glb"):
            a = str(Path(a).resolve())
        out.append(a)
        prev = a if a.startswith("--") else None
    return out


def frame_pattern(path: str) -> str:
    """The name osr-vk --frames writes frames under: the last run of # is the frame number
    (docs/animation.md); a name without one gets .#### before its extension."""
    p = Path(path)
    return path if "#" in p.name else str(p.with_name(f"{p.stem}.####{p.suffix}"))


def numbered(path: str, n: int) -> str:
    """Frame n's file: frame_pattern's last run of # replaced by n, zero-padded to its length."""
    p = Path(frame_pattern(path))
    run = re.findall(r"#+", p.name)[-1]
    i = p.name.rfind(run)
    return str(p.with_name(p.name[:i] + f"{n:0{len(run)}d}" + p.name[i + len(run):]))


def has_animation(scene: str) -> bool:
    """Whether the glTF (.gltf or .glb) holds animations: its frames are then the times of
    osr-vk --frames, else its cameras."""
    import struct
    if not Path(scene).is_file():
        return False  # the workers' check names the missing file
    try:
        data = Path(scene).read_bytes()
        if data[:4] == b"glTF":  # binary glTF: the JSON chunk follows the 12-byte header
            size = struct.unpack_from("<I", data, 12)[0]
            data = data[20:20 + size]
        return bool(json.loads(data).get("animations"))
    except (OSError, ValueError, struct.error) as e:
        raise BadInput(f"{scene}: cannot read the glTF ({e})") from None


def png_complete(path: str) -> bool:
    try:
        with open(path, "rb") as f:
            head = f.read(8)
            f.seek(-12, os.SEEK_END)
            tail = f.read(12)
    except OSError:
        return False
    return head == b"\x89PNG\r\n\x1a\n" and tail[4:8] == b"IEND"


def exr_complete(path: str, width=None, height=None) -> bool:
    try:
        exr_file.check_complete(path, width, height, ["R", "G", "B"])
        return True
    except (OSError, exr_file.ExrError):
        return False


class Task:
    def __init__(self, name: str, cmd: list[str], outputs: list[str], complete, marker: str | None = None):
        self.name, self.cmd, self.outputs, self.complete, self.marker = name, cmd, outputs, complete, marker


def split(n: int, parts: int) -> list[int]:
    """Boundaries of `parts` near-equal runs of n pixels."""
    return [round(i * n / parts) for i in range(parts + 1)]


def image_size(osr_vk: str, args: list[str]) -> tuple[int, int]:
    """The whole image's size as osr-vk chooses it (--width/--height or the camera's aspect):
    asked of osr-vk itself with a window larger than any image, which it refuses naming the
    image's size before any device work."""
    w, h = option_value(args, "--width"), option_value(args, "--height")
    if w and h and w.isdigit() and h.isdigit():
        return int(w), int(h)
    probe = replace_option(args, "--crop", "0,0,16384,16384")
    r = subprocess.run([osr_vk] + probe, capture_output=True, text=True, timeout=120)
    m = re.search(r"is not inside the (\d+)x(\d+) image", r.stderr)
    if not m:
        raise BadInput(first_error_line(r.stderr) or "osr-vk did not say the image size")
    return int(m.group(1)), int(m.group(2))


def frame_tasks(spec: str, osr_vk: str, args: list[str]) -> tuple[list[Task], dict]:
    m = re.fullmatch(r"(\d+)-(\d+)", spec)
    if not m or int(m.group(1)) > int(m.group(2)):
        raise BadInput(f"frames: '{spec}' is not a range A-B with A <= B")
    scene = [a for a in positional(args) if Path(a).suffix in (".gltf", ".glb")][0]
    animated = has_animation(scene)
    if option_value(args, "--frames") is not None:
        raise BadInput("frames: the farm gives each task its --frames; leave it out of the osr-vk arguments")
    if not animated and option_value(args, "--camera") is not None:
        raise BadInput("frames: the scene has no animation, so frame N is glTF camera N; leave --camera out")
    exr, png = option_value(args, "--offline"), option_value(args, "--png")
    tasks = []
    for n in range(int(m.group(1)), int(m.group(2)) + 1):
        # An animated scene: frame N of osr-vk --frames (its time N / fps), alone: a task has no
        # frames before it to reuse (--temporal-reuse 0, the seed as given). Otherwise camera N.
        a = (replace_option(replace_option(args, "--frames", f"{n}-{n}"), "--temporal-reuse", "0")
             if animated else replace_option(args, "--camera", str(n)))
        outs = []
        for option, path in (("--offline", exr), ("--png", png)):
            if path:
                a = replace_option(a, option, frame_pattern(path) if animated else numbered(path, n))
                outs.append(numbered(path, n))
        complete = (lambda outs=outs: all(exr_complete(o) if o.endswith(".exr") else png_complete(o) for o in outs))
        tasks.append(Task(f"frame {n}", [osr_vk] + a, outs, complete))
    return tasks, {}


def tile_tasks(spec: str, osr_vk: str, args: list[str], margin_opt: int | None) -> tuple[list[Task], dict]:
    m = re.fullmatch(r"(\d+)x(\d+)", spec)
    if not m or int(m.group(1)) < 1 or int(m.group(2)) < 1:
        raise BadInput(f"tiles: '{spec}' is not ROWSxCOLUMNS (e.g. 2x2)")
    rows, cols = int(m.group(1)), int(m.group(2))
    out = option_value(args, "--offline")
    if not out:
        raise BadInput("tiles: the osr-vk arguments need --offline OUT.exr (the assembled image)")
    if option_value(args, "--png") or option_value(args, "--crop") or option_value(args, "--dump-maps"):
        raise BadInput("tiles: --png, --crop and --dump-maps are not assembled from tiles; leave them out")
    mode = option_value(args, "--mode") or "path"  # osr-vk's default mode
    grid = int(option_value(args, "--grid-start") or 16)
    margin = margin_opt if margin_opt is not None else (2 * grid if mode == "osr" else 0)
    width, height = image_size(osr_vk, args)
    xs, ys = split(width, cols), split(height, rows)
    smallest = min(min(b - a for a, b in zip(xs, xs[1:])), min(b - a for a, b in zip(ys, ys[1:])))
    if smallest < max(MIN_TILE, margin):
        raise BadInput(f"tiles: {rows}x{cols} tiles of the {width}x{height} image are {smallest} px across, "
                       f"under {max(MIN_TILE, margin)} (the margin {margin} or {MIN_TILE} px)")
    work = Path(out).with_name(Path(out).name + ".tiles")
    tasks, layout = [], []
    for r in range(rows):
        for c in range(cols):
            x0, x1 = max(0, xs[c] - margin), min(width, xs[c + 1] + margin)
            y0, y1 = max(0, ys[r] - margin), min(height, ys[r + 1] + margin)
            path = str(work / f"r{r}c{c}.exr")
            a = replace_option(replace_option(args, "--offline", path), "--crop", f"{x0},{y0},{x1 - x0},{y1 - y0}")
            complete = (lambda p=path, w=x1 - x0, h=y1 - y0: exr_complete(p, w, h))
            tasks.append(Task(f"tile r{r}c{c}", [osr_vk] + a, [path], complete))
            layout.append({"path": path, "window": [x0, y0], "inner": [xs[c], ys[r], xs[c + 1], ys[r + 1]]})
    return tasks, {"work": work, "out": out, "width": width, "height": height, "layout": layout,
                   "margin": margin, "job": {"args": args, "tiles": spec, "margin": margin}}


def assemble(info: dict) -> None:
    """Pastes each tile's inner part into one EXR with every layer; pixels are copied as bits."""
    canvas = {}
    for t in info["layout"]:
        h, ch = exr_file.read_raw(t["path"])
        ox, oy = t["window"]
        ax, ay, bx, by = t["inner"]
        for name, ptype in h["channels"]:
            if name not in canvas:
                canvas[name] = (ptype, __import__("numpy").zeros((info["height"], info["width"]), ch[name].dtype))
            canvas[name][1][ay:by, ax:bx] = ch[name][ay - oy:by - oy, ax - ox:bx - ox]
    exr_file.write_raw(info["out"], canvas)


def dataset_tasks(spec: str, args: list[str], osr_vk: str) -> tuple[list[Task], dict]:
    try:
        seeds = parse_seeds([spec])
    except ValueError as e:
        raise BadInput(f"dataset: {e}") from None
    if not args or args[0].startswith("-"):
        raise BadInput("dataset: the arguments after -- start with the dataset folder OUT")
    out = Path(args[0]).resolve()
    rest = args[1:]
    if "--seeds" in rest or "--scenes" in rest or "--osr-vk" in rest:
        raise BadInput("dataset: --seeds, --scenes and --osr-vk are the farm's to set")
    tasks = []
    for s in seeds:
        shard = out / "shards" / str(s)
        marker = str(shard / "farm_done.json")
        cmd = [sys.executable, str(HERE / "make_dataset.py"), str(shard), "--seeds", str(s),
               "--scenes", str(out / "scenes"), "--osr-vk", osr_vk] + rest
        tasks.append(Task(f"seed {s}", cmd, [str(shard)], lambda m=marker: os.path.isfile(m), marker))
    return tasks, {"out": out, "seeds": seeds}


def merge_dataset(info: dict) -> None:
    out, shards, settings = info["out"], [], None
    for s in info["seeds"]:
        m = json.loads((out / "shards" / str(s) / "dataset.json").read_text())
        settings = m["settings"]
        for sh in m["shards"]:
            shards.append(dict(sh, path=f"shards/{s}/{sh['path']}"))
    total, secs = sum(s["count"] for s in shards), sum(s["seconds"] for s in shards)
    manifest = {"format": "osr-vk dataset", "settings": settings, "shards": shards, "examples": total,
                "seconds": round(secs, 1), "examples_per_second": round(total / max(secs, 1e-9), 2)}
    tmp = out / "dataset.json.tmp"
    tmp.write_text(json.dumps(manifest, indent=1) + "\n")
    tmp.replace(out / "dataset.json")


class Progress:
    def __init__(self, total: int):
        self.total, self.tty, self.t0, self.last = total, sys.stderr.isatty(), time.monotonic(), None

    def show(self, done: int, failed: int, retried: int, final: bool = False) -> None:
        line = (f"{PROG}: [{'#' * (20 * done // max(self.total, 1)):<20}] {done}/{self.total} tasks done, "
                f"{failed} failed, {retried} retried, {time.monotonic() - self.t0:.0f} s")
        if line != self.last:
            print(("\r" if self.tty else "") + line, end="" if self.tty else "\n", file=sys.stderr, flush=True)
            self.last = line
        if final and self.tty:
            print(file=sys.stderr)


def attempts_on_scheduler(dask_scheduler=None, keys=()) -> dict:
    """How many times each task was sent to a worker (more than once: its worker died)."""
    out = {}
    for k in keys:
        out[k] = sum(1 for t in dask_scheduler.story(k) if len(t) > 2 and t[2] == "processing")
    return out


def connect(args):
    import logging
    from distributed import Client, LocalCluster
    logging.getLogger("distributed").setLevel(logging.ERROR)  # the farm's own lines say what happens
    # Nor asyncio's: on a loaded machine an internal future of Dask's client can time out while
    # it closes, and asyncio logs "Future exception was never retrieved" with the TimeoutError
    # at exit, after the farm's one line (seen in tools/osr_farm_bad under a cold full run).
    logging.getLogger("asyncio").setLevel(logging.CRITICAL)
    timeout = args.connect_timeout
    try:
        if args.scheduler:
            return Client(args.scheduler, timeout=timeout), None
        if args.scheduler_file:
            if not Path(args.scheduler_file).is_file():
                raise BadInput(f"--scheduler-file: {args.scheduler_file}: no such file")
            return Client(scheduler_file=args.scheduler_file, timeout=timeout), None
    except (OSError, TimeoutError) as e:
        where = args.scheduler or args.scheduler_file
        raise BadInput(f"cannot reach the scheduler {where}: {str(e).splitlines()[0] if str(e) else type(e).__name__}") from None
    cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=logging.CRITICAL)
    return Client(cluster), cluster


def check_workers(client, osr_vk: str, inputs: list[str]) -> tuple[str, int]:
    workers = client.scheduler_info()["workers"]
    if not workers:
        raise BadInput("the cluster has no workers")
    versions = client.run(worker_version, osr_vk)
    local = worker_version(osr_vk) if Path(osr_vk).is_file() else None
    want = local if local and local.startswith("osr-vk ") else sorted(versions.values())[0]
    for w, v in sorted(versions.items()):
        if v != want:
            raise BadInput(f"worker {w}: {v}, not this build's {want}")
    missing = client.run(worker_missing, inputs)
    for w, m in sorted(missing.items()):
        if m:
            raise BadInput(f"worker {w}: {m[0]}: no such file")
    return want, len(workers)


def run_job(client, tasks: list[Task], progress: Progress) -> tuple[list[dict], int, int]:
    """Submits tasks, resubmits a failed one once and stops when a task fails twice the same way."""
    from distributed import as_completed
    results, failed, errors, keys = [], 0, {}, {}
    futures = {}
    for i, t in enumerate(tasks):
        f = client.submit(run_task, t.name, t.cmd, t.marker, key=f"osr-{os.getpid()}-{i}-0", pure=False)
        futures[f] = (t, 0)
        keys[f.key] = t.name
    ac = as_completed(list(futures), with_results=False)
    retried_by_us = 0
    progress.show(0, 0, 0)
    for f in ac:
        t, attempt = futures.pop(f)
        if f.status == "finished":
            results.append(f.result())
        else:
            failed += 1
            err = f.exception()
            message = str(err).splitlines()[0] if str(err) else type(err).__name__
            if type(err).__name__ == "KilledWorker":
                message = "its workers died every time it ran"
            if errors.get(t.name) == message or attempt >= 2:
                for other in futures:
                    other.cancel()
                raise JobFailed(f"{t.name}: {message}")
            errors[t.name] = message
            retried_by_us += 1
            nf = client.submit(run_task, t.name, t.cmd, t.marker, key=f"{f.key[:f.key.rfind('-')]}-{attempt + 1}", pure=False)
            futures[nf] = (t, attempt + 1)
            keys[nf.key] = t.name
            ac.add(nf)
        attempts = client.run_on_scheduler(attempts_on_scheduler, keys=list(keys))
        progress.show(len(results), failed, retried_by_us + sum(max(0, a - 1) for a in attempts.values()))
    attempts = client.run_on_scheduler(attempts_on_scheduler, keys=list(keys))
    retried = retried_by_us + sum(max(0, a - 1) for a in attempts.values())
    progress.show(len(results), failed, retried, final=True)
    return results, failed, retried


def run_here(tasks: list[Task], progress: Progress) -> tuple[list[dict], int, int]:
    """The tasks one after another in this process, with run_job's rule for failures."""
    results, failed, retried = [], 0, 0
    progress.show(0, 0, 0)
    for t in tasks:
        first = None
        while True:
            try:
                results.append(run_task(t.name, t.cmd, t.marker))
                break
            except RuntimeError as e:
                failed += 1
                if first is not None:
                    raise JobFailed(f"{t.name}: {e}") from None
                first, retried = str(e), retried + 1
            progress.show(len(results), failed, retried)
        progress.show(len(results), failed, retried)
    progress.show(len(results), failed, retried, final=True)
    return results, failed, retried


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--" in argv:
        cut = argv.index("--")
        own, job_args = argv[:cut], argv[cut + 1:]
    else:
        own, job_args = argv, []
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("kind", choices=["frames", "tiles", "dataset"])
    p.add_argument("spec", help="frames A-B | tiles RxC | dataset seeds (1-40 or 1,5,9)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--workers", type=positive_int, default=2, help="LocalCluster workers (default 2)")
    g.add_argument("--scheduler", help="tcp://HOST:PORT of a running Dask scheduler")
    g.add_argument("--scheduler-file", help="the scheduler file of a running cluster (dask-scheduler --scheduler-file)")
    g.add_argument("--here", action="store_true",
                   help="no cluster: run the tasks one after another in this process (a Slurm job array's task)")
    p.add_argument("--osr-vk", default=str(HERE.parent / "build" / "osr-vk"),
                   help="osr-vk on the workers (the same path everywhere; default build/osr-vk)")
    p.add_argument("--margin", type=int, help="tiles: pixels rendered around each tile (default: 2 x --grid-start for osr, 0 otherwise)")
    p.add_argument("--connect-timeout", type=float, default=10.0, help="seconds to reach --scheduler (default 10)")
    args = p.parse_args(own)
    if not job_args:
        p.error("the job's arguments follow --")
    t0 = time.monotonic()
    client = cluster = None
    try:
        osr_vk = str(Path(args.osr_vk).resolve()) if os.sep in args.osr_vk else args.osr_vk
        if args.kind != "dataset":
            job_args = absolute_paths(job_args)
            if not option_value(job_args, "--offline") and not option_value(job_args, "--png"):
                raise BadInput("the osr-vk arguments need --offline OUT.exr or --png OUT.png (no viewer on a farm)")
            job_args = [a for a in job_args if a != "--quiet"]  # its last line carries the render time
            scenes = [a for a in positional(job_args) if Path(a).suffix in (".gltf", ".glb")]
            if len(scenes) != 1:
                raise BadInput("the osr-vk arguments need one scene (.gltf or .glb)")
            inputs = scenes + [v for v in (option_value(job_args, "--env"), option_value(job_args, "--weights"))
                               if v and v != "none"]
        else:
            inputs = []
        if args.kind != "dataset" and not Path(osr_vk).is_file():
            raise BadInput(f"--osr-vk: {osr_vk}: no such file (build it or pass --osr-vk)")
        if args.kind == "frames":
            tasks, info = frame_tasks(args.spec, osr_vk, job_args)
        elif args.kind == "tiles":
            tasks, info = tile_tasks(args.spec, osr_vk, job_args, args.margin)
        else:
            tasks, info = dataset_tasks(args.spec, job_args, osr_vk)
        if args.here:
            version, nworkers = worker_version(osr_vk), 1
            missing = worker_missing(inputs)
            if missing:
                raise BadInput(f"{missing[0]}: no such file")
        else:
            client, cluster = connect(args)
            version, nworkers = check_workers(client, osr_vk, inputs)
        if args.kind == "tiles":
            # Tiles of another job (other arguments, grid or margin) are not this image's.
            job_file = info["work"] / "job.json"
            job = json.dumps(dict(info["job"], version=version), sort_keys=True)
            if info["work"].is_dir() and (not job_file.is_file() or job_file.read_text() != job):
                shutil.rmtree(info["work"])
            info["work"].mkdir(parents=True, exist_ok=True)
            job_file.write_text(job)
        skipped = [t for t in tasks if t.complete()]
        todo = [t for t in tasks if t not in skipped]
        for t in todo:
            for o in t.outputs:
                Path(o).parent.mkdir(parents=True, exist_ok=True)
        run = run_here if args.here else lambda todo, progress: run_job(client, todo, progress)
        results, failed, retried = run(todo, Progress(len(todo)))
        assembled = time.monotonic()
        if args.kind == "tiles":
            assemble(info)
        elif args.kind == "dataset":
            merge_dataset(info)
        assemble_s = time.monotonic() - assembled
        wall = [r["wall_s"] for r in results]
        render = [r["render_s"] for r in results if r["render_s"] is not None]
        elapsed = time.monotonic() - t0
        summary = {
            "job": args.kind, "spec": args.spec, "osr_vk": version, "workers": nworkers,
            "tasks": len(tasks), "rendered": len(results), "skipped": len(skipped),
            "failed": failed,  # attempts that failed and were run again (the job completed)
            "retried": retried, "seconds": round(elapsed, 2),
            "task_wall_s_mean": round(sum(wall) / len(wall), 3) if wall else None,
            "task_render_s_mean": round(sum(render) / len(render), 3) if render else None,
            # Process start, scene load, BVH build and writing: the task's time outside its render.
            "task_setup_s_mean": round((sum(wall) - sum(render)) / len(render), 3) if render and len(render) == len(wall) else None,
            # The cluster's own cost: the job's time beyond its tasks' wall time spread over the workers.
            # (It includes the cluster's start, the checks before submitting and the assembly.)
            "scheduling_s": round(elapsed - sum(wall) / nworkers, 2) if wall else None,
            "outputs": [info["out"]] if args.kind == "tiles" else [o for t in tasks for o in t.outputs],
            "task_results": sorted(results, key=lambda r: r["task"]),
        }
        if args.kind == "tiles":
            summary["margin"] = info["margin"]
            summary["assemble_s"] = round(assemble_s, 2)
            summary["outputs"] = [str(info["out"])]
        if args.kind == "dataset":
            summary["outputs"] = [str(info["out"] / "dataset.json")]
        print(json.dumps(summary, indent=1))
        return 0
    except BadInput as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 2
    except JobFailed as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()


if __name__ == "__main__":
    sys.exit(main())
