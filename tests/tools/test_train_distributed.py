#!/usr/bin/python3
"""tools/train.py data-parallel under torchrun (2 processes, gloo on CPU) against one process
with the same total batch, seed and steps (docs/farm.md): the runs take the same steps, both
learn (validation error well under the untrained network's), and end within noise of each other
(BatchNorm statistics are taken per process's half batch, so not bit for bit); a batch that does
not divide among the processes is one line, exit 2. Quick: synthetic maps (a smooth hemisphere
pattern per map, the one-shot input its noisy copy), a K=4 network, 40 steps.

Run by CTest (tools/train_distributed); no device.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TRAIN = ROOT / "tools" / "train.py"


def write_dataset(folder: Path, seeds: list[int], per_shard: int = 48) -> None:
    """make_dataset.py's layout (dataset.json, shards of input.npy/target.npy) with made-up maps."""
    shards = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        v, u = np.meshgrid(np.linspace(0, 1, 32), np.linspace(0, 1, 32), indexing="ij")
        level = rng.uniform(0.2, 2.0, (per_shard, 3, 1, 1))
        phase = rng.uniform(0, 6.3, (per_shard, 1, 1, 1))
        target = (level * (1.2 + np.sin(3 * u + phase) * np.cos(2 * v))).astype(np.float32)
        x = np.zeros((per_shard, 7, 32, 32), np.float32)
        x[:, 0:3] = target * rng.gamma(2.0, 0.5, target.shape)  # one path per texel: noisy
        x[:, 5] = 1.0  # normals +Z
        x[:, 6] = rng.uniform(0.5, 3.0, (per_shard, 32, 32))
        name = f"{seed}_c0"
        (folder / name).mkdir(parents=True)
        np.save(folder / name / "input.npy", x)
        np.save(folder / name / "target.npy", target)
        shards.append({"path": name, "count": per_shard, "seed": seed, "camera": 0, "seconds": 0.0})
    (folder / "dataset.json").write_text(json.dumps({
        "format": "osr-vk dataset", "shards": shards,
        "settings": {"grid": 16, "width": 64, "height": 64, "views": 1, "reference_spp": 16}}))


class Distributed(unittest.TestCase):
    def test_two_processes_train_as_one(self):
        with tempfile.TemporaryDirectory() as tmp:
            t = Path(tmp)
            write_dataset(t / "data", [1, 2, 3])
            write_dataset(t / "val", [9])
            common = [str(t / "data"), "--val", str(t / "val"), "--k", "4", "--steps", "40", "--batch", "16",
                      "--lr", "3e-3", "--threads", "1", "--seed", "3", "--no-export", "--eval-s", "1e9",
                      "--checkpoint-s", "1e9"]
            env = dict(os.environ, OMP_NUM_THREADS="1")
            one = subprocess.run([sys.executable, TRAIN, *common, "--out", str(t / "one")], env=env,
                                 capture_output=True, text=True, timeout=300)
            self.assertEqual(one.returncode, 0, one.stderr[-2000:])
            two = subprocess.run([sys.executable, "-m", "torch.distributed.run", "--standalone", "--redirects", "2", "--tee", "2", "--nproc_per_node",
                                  "2", TRAIN, *common, "--out", str(t / "two")], env=env,
                                 capture_output=True, text=True, timeout=300)
            self.assertEqual(two.returncode, 0, two.stderr[-3000:])
            self.assertIn("2 processes of 8 maps a batch", two.stderr)
            logs = {}
            for run in ("one", "two"):
                lines = (t / run / "train.log").read_text().splitlines()
                self.assertEqual(len(lines), 1, f"{run}: one validation at the end, by one process")
                logs[run] = json.loads(lines[0])
            self.assertEqual(logs["one"]["step"], 40)
            self.assertEqual(logs["two"]["step"], 40)
            self.assertEqual(logs["one"]["examples"], logs["two"]["examples"])
            # Both learned: the untrained network's error (a run of 1 step) is far above.
            untrained = subprocess.run([sys.executable, TRAIN, *common, "--steps", "1", "--lr", "1e-9",
                                        "--out", str(t / "zero")], env=env, capture_output=True, text=True,
                                       timeout=300)
            self.assertEqual(untrained.returncode, 0, untrained.stderr[-2000:])
            e0 = json.loads((t / "zero" / "train.log").read_text().splitlines()[0])["val_relmse"]
            e1, e2 = logs["one"]["val_relmse"], logs["two"]["val_relmse"]
            self.assertLess(max(e1, e2), 0.8 * e0, (e0, e1, e2))
            # The same run within noise: closer to each other than either is to the start.
            self.assertLess(abs(e1 - e2), 0.25 * (e0 - min(e1, e2)), (e0, e1, e2))
            import torch
            w1 = torch.load(t / "one" / "best.pt", map_location="cpu")
            w2 = torch.load(t / "two" / "best.pt", map_location="cpu")
            self.assertEqual(w2["processes"], 2)
            conv = [k for k, v in w1["state_dict"].items() if k.endswith("weight") and v.dim() == 4][0]
            a, b = w1["state_dict"][conv], w2["state_dict"][conv]
            self.assertLess(float((a - b).norm() / a.norm()), 0.2, conv)
            # A batch the processes cannot share evenly.
            bad = subprocess.run([sys.executable, "-m", "torch.distributed.run", "--standalone", "--redirects", "2", "--tee", "2", "--nproc_per_node",
                                  "2", TRAIN, *common, "--batch", "15", "--out", str(t / "bad")], env=env,
                                 capture_output=True, text=True, timeout=300)
            self.assertNotEqual(bad.returncode, 0)
            self.assertIn("train.py: --batch 15 does not divide among 2 processes", bad.stderr)
            self.assertFalse((t / "bad").exists())


if __name__ == "__main__":
    unittest.main(verbosity=2)
