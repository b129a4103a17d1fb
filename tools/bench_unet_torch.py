#!/usr/bin/python3
"""Times tools/unet.py's UNet forward pass in PyTorch: the peer of `osr-bench unet`.

usage: bench_unet_torch.py --k K --batch N --threads T [--min-seconds S] [--chunk C]

Prints one JSON object: {"maps_per_s": ..., "seconds": ..., "reps": ...,
"cpu_ms_per_map": process CPU time per map, "torch": version, "threads": T}. Batches above --chunk maps run as consecutive chunks, as the Vulkan engine does,
which bounds memory at K=64 (a 4096-map batch would otherwise hold ~8 GB of activations).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--k", type=int, required=True)
    parser.add_argument("--batch", type=int, required=True)
    parser.add_argument("--threads", type=int, required=True)
    parser.add_argument("--min-seconds", type=float, default=2.0)
    parser.add_argument("--chunk", type=int, default=1024)
    args = parser.parse_args()
    import torch
    import unet
    torch.set_num_threads(args.threads)
    torch.set_grad_enabled(False)
    model = unet.UNet(args.k)
    unet.randomize(model, 1)
    x = torch.rand((args.batch, 7, 32, 32)) * 2 - 0.5

    def run() -> None:
        for first in range(0, args.batch, args.chunk):
            model(x[first:first + args.chunk])

    run()  # warm-up: allocator, oneDNN primitive caches
    reps, start, cpu_start = 0, time.perf_counter(), time.process_time()
    while True:
        run()
        reps += 1
        elapsed = time.perf_counter() - start
        if elapsed >= args.min_seconds:
            break
    cpu = time.process_time() - cpu_start
    print(json.dumps({"maps_per_s": args.batch * reps / elapsed, "seconds": elapsed, "reps": reps,
                      "cpu_ms_per_map": 1e3 * cpu / (args.batch * reps),
                      "torch": torch.__version__, "threads": torch.get_num_threads()}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
