#!/usr/bin/python3
"""The training side end to end, small: procedural scenes are reproducible, the 8 symmetries
turn the normal channels with the map, and tools/train_default_model.sh --quick (make_dataset
-> train -> weights_pack -> eval_maps) and `osr-vk --mode osr --weights` run on real traced
maps with the validation layer on (OSR_VALIDATION=1, set by CTest) and no validation
message; bad datasets and checkpoints are one line, exit 2.

Run by CTest (tools/test_training_pipeline) with OSR_BINARY_DIR naming the build folder.
"""
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import maps_data  # noqa: E402
from make_interiors import make_scene  # noqa: E402

PY = "/usr/bin/python3"


def run(cmd, **kw):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, cmd))} exited {r.returncode}:\n{r.stderr[-2000:]}")
    if "osr-vk: validation" in r.stderr:
        raise AssertionError(f"validation message from {cmd[0]}:\n{r.stderr[-2000:]}")
    return r


class Symmetries(unittest.TestCase):
    def test_normals_turn_with_the_map(self):
        # A map whose normal channels hold each texel's own direction stays so under every
        # symmetry exactly when the normals are turned with the texels.
        d = maps_data.concentric_directions()
        x = np.zeros((1, 7, 32, 32), np.float32)
        x[0, 3:6] = d
        x[0, 0] = np.arange(32 * 32).reshape(32, 32)
        for k in range(8):
            y = maps_data.symmetry(x, k, normals=True)
            np.testing.assert_allclose(y[0, 3:6], d, atol=1e-6, err_msg=f"symmetry {k}")
            self.assertEqual(sorted(y[0, 0].ravel().tolist()), sorted(x[0, 0].ravel().tolist()))
            if k:
                self.assertFalse(np.array_equal(y[0, 0], x[0, 0]), f"symmetry {k} moved nothing")

    def test_without_turning_normals_a_flip_breaks_them(self):
        d = maps_data.concentric_directions()
        x = np.zeros((1, 7, 32, 32), np.float32)
        x[0, 3:6] = d
        y = maps_data.symmetry(x, 2, normals=False)
        self.assertGreater(np.abs(y[0, 3:6] - d).max(), 0.5)


class Interiors(unittest.TestCase):
    def test_same_seed_same_files_other_seed_other_scene(self):
        with tempfile.TemporaryDirectory() as t:
            a, b, c = Path(t, "a"), Path(t, "b"), Path(t, "c")
            make_scene(7, a, 2)
            make_scene(7, b, 2)
            make_scene(8, c, 2)
            for f in sorted(p.name for p in a.iterdir()):
                self.assertEqual((a / f).read_bytes(), (b / f).read_bytes(), f)
            self.assertNotEqual((a / "scene.gltf").read_bytes(), (c / "scene.gltf").read_bytes())


class Pipeline(unittest.TestCase):
    def test_quick_mode_end_to_end_and_bad_input(self):
        # tools/train_default_model.sh --quick: two tiny scenes, a small dataset, a few steps,
        # the evaluation; then the packed model renders an OSR pass in osr-vk.
        osr_vk = Path(os.environ.get("OSR_BINARY_DIR", ROOT / "build")) / "osr-vk"
        if not osr_vk.is_file():
            self.fail(f"{osr_vk}: not built (OSR_BINARY_DIR)")
        tools = ROOT / "tools"
        with tempfile.TemporaryDirectory() as t:
            t = Path(t)
            run([tools / "train_default_model.sh", "--quick", "--work", t, "--osr-vk", osr_vk])
            x = np.load(t / "ref16" / "3_c0" / "input.npy", mmap_mode="r")
            self.assertEqual(x.shape[1:], (7, 32, 32))
            self.assertGreater(len(x), 3)
            for f in ("best.pt", "checkpoint.pt", "train.log", "model.osrw"):
                self.assertTrue((t / "run" / f).is_file(), f)
            self.assertTrue((t / "eval" / "grid.png").read_bytes().startswith(b"\x89PNG"))
            self.assertIn("U-Net K=8", (t / "eval" / "eval.md").read_text())
            run([osr_vk, "--mode", "osr", "--weights", t / "run" / "model.osrw", "--passes", "1", "--width", "32",
                 "--height", "32", "--offline", t / "o.exr", "--quiet", ROOT / "scenes" / "cornell" / "cornell.gltf"])
            self.assertTrue((t / "o.exr").is_file())
            # Resuming continues from the checkpoint instead of starting over.
            train = [PY, tools / "train.py", t / "ref16", "--val", t / "val", "--k", "8", "--batch", "4",
                     "--threads", "1", "--no-export"]
            r = run(train + ["--out", t / "run", "--steps", "6"])
            self.assertIn("resuming", r.stderr)

            def refused(cmd, needle):
                r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertEqual(r.stderr.count("\n"), 1, r.stderr)
                self.assertIn(needle, r.stderr)

            # Validation sharing a scene with the training data.
            refused([PY, tools / "train.py", t / "ref16", "--val", t / "ref16", "--out", t / "bad", "--steps", "1"],
                    "split by scene")
            # A checkpoint of another K, a truncated shard, a shard of the wrong shape.
            refused([PY, tools / "train.py", t / "ref16", "--val", t / "val", "--out", t / "bad3", "--k", "16",
                     "--init", t / "run" / "best.pt", "--steps", "1"], "best.pt")
            shard = t / "ref16" / "3_c0"
            (shard / "input.npy").write_bytes((shard / "input.npy").read_bytes()[:5000])
            refused(train + ["--out", t / "bad1", "--steps", "1"], "input.npy")
            np.save(shard / "input.npy", np.zeros((4, 6, 32, 32), np.float32))
            refused(train + ["--out", t / "bad2", "--steps", "1"], "expected [N, 7, 32, 32]")
            refused([PY, tools / "eval_maps.py", t / "val", "--weights", t / "o.exr", "--out", t / "e2"], "o.exr")


if __name__ == "__main__":
    unittest.main()
