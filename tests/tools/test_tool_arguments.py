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
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TOOLS = ROOT / "tools"
sys.path.insert(0, str(TOOLS))
from arg_types import parse_seeds  # noqa: E402

PY = "/usr/bin/python3"


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

    def test_eval_maps(self):
        self.refused("eval_maps.py", ["VAL", "--out", "OUT", "--rows", "0"], "argument --rows")


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
