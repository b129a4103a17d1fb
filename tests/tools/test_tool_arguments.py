#!/usr/bin/python3
"""The tools/ scripts on bad numbers, as a person types them: a count or budget that is zero
or negative and a seed range that runs backwards are refused at once, exit 2, with a last line
naming the option, and nothing is written. Before, train.py --steps 0 trained for the default
30 minutes, --minutes -1 never stopped, --batch 0 "trained" on nothing and packed a model,
--k 0 and --threads 0 were PyTorch tracebacks; make_interiors.py --cameras -2 made 91 cameras
and --seeds 5-1 made nothing with exit 0; make_dataset.py --cameras 0 wrote an empty dataset.

Run by CTest (tools/test_tool_arguments); seconds, no device.
"""
import subprocess
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TOOLS = ROOT / "tools"
sys.path.insert(0, str(TOOLS))
from arg_types import parse_seeds  # noqa: E402
import exr_file  # noqa: E402
import numpy as np  # noqa: E402

PY = "/usr/bin/python3"


def read_png(path: Path) -> list[list[tuple[int, int, int]]]:
    """The RGB of each pixel of a PNG that gltf_build.png() wrote (RGBA 8, filter 0)."""
    data, pos, idat = path.read_bytes(), 8, b""
    width = height = 0
    while pos < len(data):
        size, kind = int.from_bytes(data[pos:pos + 4], "big"), data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + size]
        if kind == b"IHDR":
            width, height = int.from_bytes(body[:4], "big"), int.from_bytes(body[4:8], "big")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + size
    rows = zlib.decompress(idat)
    stride = 1 + 4 * width
    return [[tuple(rows[y * stride + 1 + 4 * x:y * stride + 4 + 4 * x]) for x in range(width)]
            for y in range(height)]


class BadNumbers(unittest.TestCase):
    def refused(self, script: str, args: list[str], mention: str) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "out"
            cmd = [PY, str(TOOLS / script), *[a.replace("OUT", str(out)) for a in args]]
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
            with self.subTest(cmd=" ".join(cmd[1:])):
                self.assertEqual(r.returncode, 2, r.stderr)
                last = r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""
                self.assertIn(mention, last)
                self.assertNotIn("Traceback", r.stderr)
                self.assertFalse(out.exists(), "wrote output before refusing")

    def test_make_interiors(self):
        self.refused("make_interiors.py", ["OUT", "--seeds", "5-1"], "runs backwards")
        self.refused("make_interiors.py", ["OUT", "--seeds", "1-x"], "'1-x' is not a seed")
        self.refused("make_interiors.py", ["OUT", "--seeds", "1", "--cameras", "-2"], "--cameras")
        self.refused("make_interiors.py", ["OUT", "--seeds", "1", "--cameras", "0"], "--cameras")

    def test_make_dataset(self):
        for option in ["--cameras", "--grid", "--size", "--views", "--reference-spp"]:
            self.refused("make_dataset.py", ["OUT", "--seeds", "1", option, "0"], option)
        self.refused("make_dataset.py", ["OUT", "--seeds", "3-2"], "runs backwards")

    def test_train(self):
        for option, value in [("--steps", "0"), ("--minutes", "-1"), ("--minutes", "nan"),
                              ("--k", "0"), ("--batch", "0"), ("--threads", "0"), ("--lr", "-1"),
                              ("--eval-s", "0"), ("--checkpoint-s", "-5")]:
            self.refused("train.py", ["DATA", "--val", "VAL", "--out", "OUT", option, value],
                         f"argument {option}")

    def test_side_by_side_crop(self):
        ref = str(ROOT / "scenes" / "cornell" / "cornell_cycles_4096spp.exr")
        for crop, mention in [("1,2,3", "expected X,Y,W,H"), ("0,0,0,5", "expected X,Y,W,H"),
                              ("200,0,100,10", "reaches past")]:
            self.refused("side_by_side.py", ["OUT.png", ref, "--crop", crop], mention)
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "crop.png"
            r = subprocess.run([PY, str(TOOLS / "side_by_side.py"), str(out), ref, ref,
                                "--crop", "10,20,30,40", "--scale", "2", "--gap", "4"],
                               capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)
            width, height = int.from_bytes(out.read_bytes()[16:20], "big"), \
                int.from_bytes(out.read_bytes()[20:24], "big")
            self.assertEqual((width, height), (2 * 30 * 2 + 4, 2 * 40))

    def test_side_by_side_layer(self):
        ref = str(ROOT / "scenes" / "cornell" / "cornell_cycles_4096spp.exr")
        self.refused("side_by_side.py", ["OUT.png", ref + ":noisy"], "no RGB layer 'noisy'")
        self.refused("side_by_side.py", ["OUT.png", "missing.exr:noisy"], "missing.exr")
        with tempfile.TemporaryDirectory() as tmp:
            # A film as osr-vk writes one: the denoised colour 0 by default, the raw one 1.
            film = Path(tmp) / "film.exr"
            ones, zeros = np.ones((4, 6), np.float32), np.zeros((4, 6), np.float32)
            exr_file.write_raw(film, {**{c: (2, zeros.view(np.uint32)) for c in "RGB"},
                                      **{"noisy." + c: (2, ones.view(np.uint32)) for c in "RGB"}})
            out = Path(tmp) / "layer.png"
            r = subprocess.run([PY, str(TOOLS / "side_by_side.py"), str(out), f"{film}:noisy",
                                str(film), "--gap", "0"], capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(int.from_bytes(out.read_bytes()[16:20], "big"), 12)
            pixels = read_png(out)
            self.assertEqual(pixels[0][0], (255, 255, 255))  # the raw layer, white
            self.assertEqual(pixels[0][6], (0, 0, 0))        # the default layer, black

    def test_add_camera_path(self):
        scene = str(ROOT / "scenes" / "cornell" / "cornell.gltf")
        for option, value in [("--frames", "0"), ("--fps", "-24"), ("--arc", "0"), ("--yfov", "4")]:
            self.refused("add_camera_path.py", [scene, "OUT.gltf", option, value], option)
        self.refused("add_camera_path.py", [scene, "OUT.glb"], ".gltf")

    def test_add_object_path(self):
        scene = str(ROOT / "tests" / "data" / "scene" / "moving_object.gltf")
        move = ["--move", "1", "0", "0"]
        self.refused("add_object_path.py", [scene, "OUT.gltf", "--node", "3", *move, "--frames", "0"],
                     "--frames")
        self.refused("add_object_path.py", [scene, "OUT.gltf", "--node", "3", "--move", "nan", "0", "0"],
                     "--move")
        self.refused("add_object_path.py", [scene, "OUT.gltf", *move], "--node")
        self.refused("add_object_path.py", [scene, "OUT.gltf", "--node", "4", *move], "not a mesh node")

    def test_eval_maps(self):
        self.refused("eval_maps.py", ["VAL", "--out", "OUT", "--rows", "0"], "argument --rows")


class CameraPath(unittest.TestCase):
    """add_camera_path.py on the Cornell box: one key per frame, the new camera first in the
    scene, unit rotations, a walk inside the bounds, buffer URIs valid from another folder."""

    def test_walk(self):
        import json
        import math
        scene = ROOT / "scenes" / "cornell" / "cornell.gltf"
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "sub" / "walk.gltf"
            out.parent.mkdir()
            r = subprocess.run([PY, str(TOOLS / "add_camera_path.py"), str(scene), str(out),
                                "--frames", "6"], capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)
            doc = json.loads(out.read_text())
            anim = doc["animations"][-1]
            self.assertEqual(len(anim["channels"]), 2)
            node = anim["channels"][0]["target"]["node"]
            self.assertEqual(doc["scenes"][doc.get("scene", 0)]["nodes"][0], node)
            times = doc["accessors"][anim["samplers"][0]["input"]]
            self.assertEqual((times["count"], times["max"]), (6, [5 / 24]))
            for b in doc["buffers"]:
                uri = b["uri"]
                if not uri.startswith("data:"):
                    self.assertTrue((out.parent / uri).is_file(), uri)
            sys.path.insert(0, str(TOOLS))
            import add_camera_path as acp
            lo, hi = acp.scene_bounds(json.loads(scene.read_text()))
            keys = acp.camera_keys(lo, hi, 6, False, 90.0)
            for eye, q in keys:
                self.assertAlmostEqual(math.sqrt(sum(v * v for v in q)), 1.0, places=6)
                self.assertTrue(all(a < e < b for a, e, b in zip(lo, eye, hi)), eye)


class ObjectPath(unittest.TestCase):
    """add_object_path.py on the Cornell box: --list names each mesh node; the moved node gets
    one LINEAR translation channel, a key per frame from its rest place to rest + the move,
    eased (the first steps shorter than the middle ones)."""

    def test_slide(self):
        import json
        scene = ROOT / "scenes" / "cornell" / "cornell.gltf"
        r = subprocess.run([PY, str(TOOLS / "add_object_path.py"), str(scene), "--list"],
                           capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("7 'short' bounds", r.stdout)
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "sub" / "moving.gltf"
            out.parent.mkdir()
            r = subprocess.run([PY, str(TOOLS / "add_object_path.py"), str(scene), str(out),
                                "--node", "7", "--move", "0.2", "0", "-0.1", "--frames", "6"],
                               capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)
            doc = json.loads(out.read_text())
            anim = doc["animations"][-1]
            self.assertEqual(anim["channels"], [{"sampler": 0, "target": {"node": 7, "path": "translation"}}])
            rest = doc["nodes"][7].get("translation", [0, 0, 0])
            times = doc["accessors"][anim["samplers"][0]["input"]]
            self.assertEqual((times["count"], times["max"]), (6, [5 / 24]))
            for b in doc["buffers"]:
                if not b["uri"].startswith("data:"):
                    self.assertTrue((out.parent / b["uri"]).is_file(), b["uri"])
            values = embedded_vec3(doc, anim["samplers"][0]["output"])
            self.assertEqual(len(values), 6)
            for got, want in zip(values[0], rest):
                self.assertAlmostEqual(got, want, places=6)
            for got, want in zip(values[-1], [a + m for a, m in zip(rest, (0.2, 0, -0.1))]):
                self.assertAlmostEqual(got, want, places=6)
            steps = [abs(b[0] - a[0]) for a, b in zip(values, values[1:])]
            self.assertLess(steps[0], steps[2])


def embedded_vec3(doc: dict, accessor: int) -> list[tuple[float, ...]]:
    """The VEC3 values of an accessor in an embedded (data: URI) buffer."""
    import base64
    import struct
    acc = doc["accessors"][accessor]
    view = doc["bufferViews"][acc["bufferView"]]
    data = base64.b64decode(doc["buffers"][view["buffer"]]["uri"].split(",", 1)[1])
    start = view.get("byteOffset", 0)
    return [struct.unpack_from("<3f", data, start + 12 * i) for i in range(acc["count"])]


class Seeds(unittest.TestCase):
    def test_lists_and_ranges(self):
        self.assertEqual(parse_seeds(["1-3,7", "9"]), [1, 2, 3, 7, 9])
        self.assertEqual(parse_seeds(["4-4"]), [4])
        with self.assertRaises(ValueError):
            parse_seeds(["5-1"])
        with self.assertRaises(ValueError):
            parse_seeds(["-3"])


if __name__ == "__main__":
    unittest.main()
