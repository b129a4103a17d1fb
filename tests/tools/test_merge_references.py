#!/usr/bin/python3
"""tools/merge_references.py: the merged colour, luminance variance, channel spread and direct
and indirect layers of known parts, the spread as an estimate of the mean's noise, and bad
input refused (one line, exit 2, nothing written).

Run by CTest (tools/test_merge_references); seconds, no device.
"""
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

PY = "/usr/bin/python3"
FLOAT = 2


def write_part(path: Path, rgb: np.ndarray, variance: np.ndarray, extra: tuple[str, ...] = ()) -> None:
    channels = {c: (FLOAT, rgb[i].astype(np.float32).view(np.uint32)) for i, c in enumerate("RGB")}
    channels["variance.Y"] = (FLOAT, variance.astype(np.float32).view(np.uint32))
    for name in extra:
        channels[name] = (FLOAT, rgb[0].astype(np.float32).view(np.uint32))
    exr_file.write_raw(path, channels)


def read(path: Path) -> dict[str, np.ndarray]:
    h, raw = exr_file.read_raw(path)
    types = dict(h["channels"])
    return {c: exr_file.to_float(types[c], raw[c]).astype(np.float64) for c in types}


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([PY, str(TOOLS / "merge_references.py"), *args], capture_output=True, text=True,
                          timeout=60)


class Merge(unittest.TestCase):
    def test_known_parts(self):
        with tempfile.TemporaryDirectory() as tmp:
            a, b, out = Path(tmp, "a.exr"), Path(tmp, "b.exr"), Path(tmp, "ref.exr")
            ones = np.ones((3, 4, 5))
            write_part(a, 1.0 * ones, np.full((4, 5), 0.04))
            write_part(b, 2.0 * ones, np.full((4, 5), 0.01))
            r = run(str(out), f"{a}:100", f"{b}:300")
            self.assertEqual(r.returncode, 0, r.stderr)
            m = read(out)
            # mean 0.25 * 1 + 0.75 * 2; variance 0.25^2 0.04 + 0.75^2 0.01;
            # spread (100 (1 - 1.75)^2 + 300 (2 - 1.75)^2) / (1 * 400)
            np.testing.assert_allclose(m["R"], 1.75, rtol=1e-6)
            np.testing.assert_allclose(m["variance.Y"], 0.0625 * 0.04 + 0.5625 * 0.01, rtol=1e-6)
            np.testing.assert_allclose(m["spread.B"], (100 * 0.5625 + 300 * 0.0625) / 400, rtol=1e-6)
            self.assertNotIn("direct.R", m)  # the parts have no direct layer

    def test_layers_merged_where_every_part_has_them(self):
        with tempfile.TemporaryDirectory() as tmp:
            a, b, out = Path(tmp, "a.exr"), Path(tmp, "b.exr"), Path(tmp, "ref.exr")
            layers = tuple(f"{n}.{c}" for n in ("direct", "indirect") for c in "RGB")
            write_part(a, np.ones((3, 4, 5)), np.zeros((4, 5)), layers)  # each layer = R
            write_part(b, 3.0 * np.ones((3, 4, 5)), np.zeros((4, 5)), layers[:3])  # no indirect
            self.assertEqual(run(str(out), f"{a}:100", f"{b}:300").returncode, 0)
            m = read(out)
            np.testing.assert_allclose(m["direct.G"], 2.5, rtol=1e-6)
            # (100 (1 - 2.5)^2 + 300 (3 - 2.5)^2) / (1 * 400)
            np.testing.assert_allclose(m["direct.spread.B"], (225 + 75) / 400, rtol=1e-6)
            self.assertNotIn("indirect.R", m)

    def test_spread_estimates_the_noise_of_the_mean(self):
        # Parts of 1, 2 and 5 samples of a noise whose channels differ: over many pixels the
        # spread's mean is the mean's variance, sigma_c^2 / 8.
        rng = np.random.default_rng(3)
        sigma = np.array([0.1, 0.3, 0.05])[:, None, None]
        with tempfile.TemporaryDirectory() as tmp:
            args = []
            for i, n in enumerate((1, 2, 5)):
                p = Path(tmp, f"p{i}.exr")
                write_part(p, 1.0 + sigma / np.sqrt(n) * rng.standard_normal((3, 200, 200)), np.zeros((200, 200)))
                args.append(f"{p}:{n}")
            out = Path(tmp, "ref.exr")
            self.assertEqual(run(str(out), *args).returncode, 0)
            m = read(out)
            for i, c in enumerate("RGB"):
                self.assertAlmostEqual(m[f"spread.{c}"].mean() / (sigma[i, 0, 0] ** 2 / 8), 1.0, delta=0.03)

    def test_bad_input(self):
        with tempfile.TemporaryDirectory() as tmp:
            a, b, out = Path(tmp, "a.exr"), Path(tmp, "b.exr"), Path(tmp, "ref.exr")
            write_part(a, np.ones((3, 4, 5)), np.zeros((4, 5)))
            write_part(b, np.ones((3, 2, 5)), np.zeros((2, 5)))
            denoised = Path(tmp, "d.exr")
            write_part(denoised, np.ones((3, 4, 5)), np.zeros((4, 5)), ("noisy.R",))
            for args, mention in (([f"{a}:10"], "usage"),
                                  ([f"{a}:10", f"{b}:10"], "different sizes"),
                                  ([f"{a}:0", f"{denoised}:10"], "positive whole number"),
                                  ([f"{a}", f"{denoised}:10"], "PART.exr:SPP"),
                                  ([f"{a}:10", f"{tmp}/none.exr:10"], "none.exr"),
                                  ([f"{a}:10", f"{denoised}:10"], "denoised"),
                                  ([f"{a}:10", f"{out}:10"], "also a part"),
                                  ([f"{a}:10", f"{a}:20"], "given twice")):
                with self.subTest(args=args):
                    r = run(str(out), *args)
                    self.assertEqual(r.returncode, 2, r.stderr)
                    self.assertIn(mention, r.stderr.strip().splitlines()[-1] if mention != "usage" else r.stderr)
                    self.assertNotIn("Traceback", r.stderr)
                    self.assertFalse(out.exists())
            r = run(str(Path(tmp, "no", "ref.exr")), f"{a}:10", f"{denoised.with_name('a2.exr')}:10")
            self.assertEqual(r.returncode, 2)
            write_part(Path(tmp, "a2.exr"), np.ones((3, 4, 5)), np.zeros((4, 5)))
            r = run(str(Path(tmp, "no", "ref.exr")), f"{a}:10", f"{tmp}/a2.exr:10")
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertIn("cannot write", r.stderr.strip().splitlines()[-1])
            self.assertNotIn("Traceback", r.stderr)
            r = run("--help")
            self.assertEqual(r.returncode, 0)
            self.assertIn("spread", r.stdout)


if __name__ == "__main__":
    unittest.main()
