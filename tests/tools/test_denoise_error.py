#!/usr/bin/python3
"""tools/denoise_error.py: on films of known bias and noise against two noisy reference halves,
the error less the references' noise, its split into variance and bias, regions that add up
to the image, the per-block choice bound, and bad input refused (one line, exit 2).

Run by CTest (tools/test_denoise_error); seconds, no device.
"""
import json
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TOOLS = ROOT / "tools"
sys.path.insert(0, str(TOOLS))
import exr_file  # noqa: E402

H, W = 64, 96
FLOAT = next(t for t, (name, _) in exr_file.PIXEL_TYPES.items() if name == "FLOAT")


def write(path: Path, rgb: np.ndarray, layer: str = "") -> str:
    names = [f"{layer}.{c}" if layer else c for c in "RGB"]
    exr_file.write_raw(path, {n: (FLOAT, rgb[i].astype(np.float32).view(np.uint32)) for i, n in enumerate(names)})
    return str(path)


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["/usr/bin/python3", str(TOOLS / "denoise_error.py"), *args], capture_output=True,
                          text=True, timeout=60)


class DenoiseError(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)
        rng = np.random.default_rng(3)
        self.truth = np.full((3, H, W), 0.5)
        self.a = write(self.dir / "a.exr", self.truth + rng.normal(0, 0.02, self.truth.shape))
        self.b = write(self.dir / "b.exr", self.truth + rng.normal(0, 0.02, self.truth.shape))
        # Biased films: +0.05 on the left half, noise of sd 0.02 everywhere, 8 seeds.
        self.bias = np.zeros_like(self.truth)
        self.bias[:, :, :W // 2] = 0.05
        self.films = [write(self.dir / f"x{s}.exr", self.truth + self.bias + rng.normal(0, 0.02, self.truth.shape))
                      for s in range(8)]
        # Unbiased noisier films, sd 0.04, stored in a layer as osr-vk's raw colour is.
        self.noisy = [write(self.dir / f"y{s}.exr", self.truth + rng.normal(0, 0.04, self.truth.shape), "noisy")
                      for s in range(8)]

    def tearDown(self):
        self.tmp.cleanup()

    def lines(self, *args: str) -> list[dict]:
        r = run("--halves", self.a, self.b, *args)
        self.assertEqual(r.returncode, 0, r.stderr)
        return [json.loads(line) for line in r.stdout.splitlines()]

    def test_error_less_the_references_noise_splits_into_bias_and_variance(self):
        w = 1 / (0.25 + 0.01)
        out = self.lines("x=" + ",".join(self.films), "y=" + ",".join(f + ":noisy" for f in self.noisy),
                         "--region", "left=0,0,48,64", "--region", "right=48,0,48,64")
        x = {d["region"]: d for d in out if d["films"] == "x"}
        # Truth: bias^2 0.0025 on half the pixels, variance 0.0004, both times w. The
        # references' own noise (sd 0.02, as large as one film's) must not show.
        self.assertAlmostEqual(x["image"]["bias2"] / w, 0.00125, delta=0.0001)
        self.assertAlmostEqual(x["image"]["variance"] / w, 0.0004, delta=0.00003)
        self.assertAlmostEqual(x["image"]["relmse"], x["image"]["bias2"] + x["image"]["variance"], places=12)
        self.assertAlmostEqual(x["right"]["bias2"] / x["right"]["pixels"] / w, 0.0, delta=0.00005)
        for key in ("relmse", "variance", "bias2"):
            self.assertAlmostEqual(x["left"][key] + x["right"][key], x["image"][key], places=12)
        self.assertEqual(x["left"]["pixels"], 0.5)
        y = next(d for d in out if d["films"] == "y" and d["region"] == "image")
        self.assertAlmostEqual(y["variance"] / w, 0.0016, delta=0.0001)
        self.assertAlmostEqual(y["bias2"] / w, 0.0, delta=0.00005)
        self.assertGreater(y["top1_share"], 0.01)
        # The films' level over the references': x is 0.05 bright on the left half only.
        self.assertAlmostEqual(x["left"]["lum_ratio"], 1.1, delta=0.002)
        self.assertAlmostEqual(x["right"]["lum_ratio"], 1.0, delta=0.002)
        self.assertAlmostEqual(x["image"]["lum_ratio"], 1.05, delta=0.002)
        self.assertAlmostEqual(y["lum_ratio"], 1.0, delta=0.002)
        self.assertLessEqual(y["top1_share"], 1.0)

    def test_gate_picks_the_better_set_per_block(self):
        # (10 does not divide the 96 x 64 image: the last blocks are partial.)
        out = self.lines("--gate", "10", "x=" + ",".join(self.films), "y=" + ",".join(f + ":noisy" for f in self.noisy))
        g = next(d for d in out if d["films"] == "gate(x|y)")
        # y is better on the left (variance 0.0016 < 0.0029), x on the right (0.0004 < 0.0016):
        # the choice's error is about each side's better one, below both sets'.
        w = 1 / (0.25 + 0.01)
        self.assertAlmostEqual(g["relmse_b"] / w, (0.0016 + 0.0004) / 2, delta=0.0002)
        self.assertEqual(g["block"], 10)
        self.assertLess(g["relmse_b"], min(g["relmse_b_x"], g["relmse_b_y"]))

    def test_one_seed_has_no_split(self):
        out = self.lines("x=" + self.films[0])
        self.assertEqual(out[0]["seeds"], 1)
        self.assertNotIn("variance", out[0])

    def test_bad_input(self):
        small = write(self.dir / "small.exr", np.zeros((3, 8, 8)))
        cases = [
            (["--halves", self.a, str(self.dir / "none.exr"), "x=" + self.films[0]], "none.exr"),
            (["--halves", self.a, small, "x=" + self.films[0]], "small.exr"),
            (["--halves", self.a, self.b, "x=" + small], "small.exr"),
            (["--halves", self.a, self.b, "x=" + self.films[0] + ":noisy"], "no channel noisy.R"),
            (["--halves", self.a, self.b, self.films[0]], "not NAME=FILM.exr"),
            (["--halves", self.a, self.b, "x=" + self.films[0], "--region", "r=90,0,16,16"], "inside the 96 x 64"),
            (["--halves", self.a, self.b, "x=" + self.films[0], "--gate", "8"], "--gate"),
            (["--halves", self.a, self.b, "x=" + self.films[0], "y=" + self.films[1], "--gate", "0"], "--gate 0"),
        ]
        for args, mention in cases:
            with self.subTest(args=args[-3:]):
                r = run(*args)
                self.assertEqual(r.returncode, 2, r.stdout)
                self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
                self.assertIn(mention, r.stderr)
                self.assertEqual(r.stdout, "")


if __name__ == "__main__":
    unittest.main()
