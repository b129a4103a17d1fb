#!/usr/bin/python3
"""The training side end to end, small: procedural scenes are reproducible, the 8 symmetries
turn the normal channels with the map, a map traced in a turned scene is the turned map, and
tools/train_default_model.sh --quick (make_dataset -> train -> weights_pack -> eval_maps) and
`osr-vk --mode osr --weights` run on real traced maps with the validation layer on (OSR_VALIDATION=1, set by CTest) and no validation
message; bad datasets and checkpoints are one line, exit 2.

Run by CTest (tools/test_training_pipeline) with OSR_BINARY_DIR naming the build folder.
"""
import math
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


def write_asymmetric_scene(path: Path, turn_degrees: float) -> None:
    """A floor point at the origin (normal +Y) seen by a camera straight above it, surrounded by
    differently coloured boxes at different distances and a lamp off to one side; the whole
    scene, camera included, turned by turn_degrees about +Y through the origin."""
    from gltf_build import Gltf
    g = Gltf()
    g.doc["extensionsUsed"] = ["KHR_materials_emissive_strength"]

    def material(rgb, emit=None):
        m = {"pbrMetallicRoughness": {"baseColorFactor": [*rgb, 1], "metallicFactor": 0, "roughnessFactor": 1}}
        if emit:
            m.update({"emissiveFactor": [1, 1, 1], "doubleSided": True,
                      "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": emit}}})
        return g.add("materials", m)

    def box(lo, hi, mat):
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        faces = [((1, 0, 0), [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)]),
                 ((-1, 0, 0), [(x0, y0, z1), (x0, y1, z1), (x0, y1, z0), (x0, y0, z0)]),
                 ((0, 1, 0), [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)]),
                 ((0, -1, 0), [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)]),
                 ((0, 0, 1), [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]),
                 ((0, 0, -1), [(x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)])]
        pos, nrm, idx = [], [], []
        for n, quad in faces:
            b = len(pos)
            pos += quad
            nrm += [n] * 4
            idx += [b, b + 1, b + 2, b, b + 2, b + 3]
        return g.node(root=False, mesh=g.mesh(pos, idx, nrm, material=mat))

    children = [
        box((-4, -0.1, -4), (4, 0, 4), material((0.7, 0.7, 0.7))),        # floor
        box((1.2, 0, -0.5), (1.6, 1.5, 2.5), material((0.8, 0.1, 0.1))),   # red wall, +x
        box((-2.0, 0, -1.8), (0.3, 2.2, -1.4), material((0.1, 0.7, 0.1))),  # green, -z
        box((-1.6, 0, 0.6), (-0.9, 0.5, 1.3), material((0.1, 0.2, 0.8))),  # low blue, -x +z
        box((-0.2, 2.9, 0.6), (0.9, 3.0, 1.1), material((0, 0, 0), emit=30)),  # lamp
    ]
    down = [-math.sin(math.pi / 4), 0, 0, math.cos(math.pi / 4)]  # camera -Z onto -Y
    g.add("cameras", {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1}})
    children.append(g.node(root=False, camera=0, translation=[0, 0.6, 0], rotation=down))
    half = math.radians(turn_degrees) / 2
    g.node(children=children, rotation=[0, math.sin(half), 0, math.cos(half)])
    g.gltf(path)


class TracedInARotatedFrame(unittest.TestCase):
    def test_rotated_map_equals_the_map_of_the_rotated_scene(self):
        # Turning the scene (camera included) about the floor point's normal leaves the map
        # frame (a function of the normal) where it was, so the map traced there is the map of
        # the unturned scene turned about z: one of maps_data.symmetry's rotations, with the
        # hit normals turned too. Radiance from 64 paths per texel; normals and distances
        # from the one-shot input.
        osr_vk = Path(os.environ.get("OSR_BINARY_DIR", ROOT / "build")) / "osr-vk"
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            maps = {}
            for turn in (0, 90, -90, 180):
                scene = tmp / f"turn{turn}.gltf"
                write_asymmetric_scene(scene, turn)
                out = tmp / f"maps{turn}"
                run([osr_vk, "maps", scene, "--out", out, "--pixels", "32,32", "--width", "64",
                     "--height", "64", "--reference-spp", "64", "--quiet"])
                maps[turn] = (np.load(out / "input.npy"), np.load(out / "target.npy"))
            x0, t0 = maps[0]
            self.assertEqual(x0.shape, (1, 7, 32, 32))

            def radiance_error(t, k):
                u = maps_data.symmetry(t0, k, normals=False)
                return float(np.abs(u - t).mean() / t.mean())

            found = {}
            for turn in (90, -90, 180):
                x, t = maps[turn]
                errors = [radiance_error(t, k) for k in range(8)]
                best = int(np.argmin(errors))
                second = sorted(errors)[1]
                found[turn] = best
                # Noise of 64 paths per texel against what a wrong symmetry costs.
                self.assertLess(errors[best], 0.2, f"turn {turn}: {errors}")
                self.assertLess(errors[best], 0.5 * second, f"turn {turn}: {errors}")
                # Hit normals and distances turn with it (texels whose one path hit something
                # in both maps; a texel's jittered path may cross an edge, hence the median).
                u = maps_data.symmetry(x0, best, normals=True)
                hit = (u[0, 6] > 0) & (x[0, 6] > 0)
                self.assertGreater(hit.mean(), 0.2)  # open above: the boxes, the lamp and the floor
                normal_gap = np.abs(u[0, 3:6] - x[0, 3:6]).sum(axis=0)[hit]
                self.assertLess(float(np.median(normal_gap)), 1e-3, f"turn {turn}")
                self.assertGreater(float((normal_gap < 0.05).mean()), 0.9, f"turn {turn}")
                self.assertLess(float(np.median(np.abs(u[0, 6] - x[0, 6])[hit])), 0.05)
                if best:  # every turn moves the normals: unturned ones must not match
                    v = maps_data.symmetry(x0, best, normals=False)
                    self.assertGreater(float(np.median(np.abs(v[0, 3:6] - x[0, 3:6]).sum(axis=0)[hit])), 0.05)
            # Quarter turns are the square's rotations (transpose + one flip: k 3 or 5), opposite
            # ones for opposite turns, and a half turn both flips (k 6).
            self.assertEqual(sorted([found[90], found[-90]]), [3, 5], found)
            self.assertEqual(found[180], 6, found)
            print("rotations found (turn: symmetry):", found, file=sys.stderr)


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
