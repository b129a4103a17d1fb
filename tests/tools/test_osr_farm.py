#!/usr/bin/python3
"""tools/osr_farm.py on a LocalCluster of 2 workers (docs/farm.md): a 4-frame shot, then the
same job resumed after one frame was deleted and one cut short (only those two render again);
a worker SIGKILLed during the shot (the shot still completes); 2 x 2 tiles equal to one render
bit for bit in path mode and within noise with no seam in OSR mode; bad input (an unreachable
scheduler, a scene missing, another osr-vk build on one worker of a --scheduler-file cluster,
a tile grid that does not divide): one line, exit 2, nothing overwritten.

usage: test_osr_farm.py shot|kill|tiles|bad   (one CTest each; OSR_BINARY_DIR names the build)
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path


ROOT = Path(__file__).resolve().parents[2]
TOOLS = ROOT / "tools"
sys.path.insert(0, str(TOOLS))
import exr_file  # noqa: E402
import tile_seams  # noqa: E402
from make_interiors import make_scene  # noqa: E402

PY = "/usr/bin/python3"
OSR_VK = Path(os.environ.get("OSR_BINARY_DIR", ROOT / "build")) / "osr-vk"
CORNELL = str(ROOT / "scenes" / "cornell" / "cornell.gltf")
SHOT = ["--mode", "path", "--spp", "1", "--seed", "3", "--width", "64", "--height", "64"]


def farm(*args, check=True, **kw):
    r = subprocess.run([PY, str(TOOLS / "osr_farm.py"), *map(str, args)], capture_output=True, text=True,
                       timeout=300, **kw)
    if check and r.returncode != 0:
        raise AssertionError(f"osr_farm.py exit {r.returncode}: {r.stderr[-2000:]}")
    return r


def summary(r) -> dict:
    return json.loads(r.stdout)


def layers(path) -> dict:
    return exr_file.read_raw(path)[1]


def floats(path) -> dict:
    h, ch = exr_file.read_raw(path)
    return {c: exr_file.to_float(t, ch[c]) for c, t in h["channels"]}


class Farm(unittest.TestCase):
    def setUp(self):
        if not OSR_VK.is_file():
            self.fail(f"{OSR_VK}: not built (OSR_BINARY_DIR)")
        self.tmp = Path(tempfile.mkdtemp(prefix="osr_farm_"))
        self.scene = self.tmp / "scene"
        make_scene(3, self.scene, 4)  # an interior with 4 cameras: a 4-frame shot

    def shot_args(self, out="shot.exr"):
        return ["--osr-vk", OSR_VK, "--", *SHOT, "--offline", self.tmp / out, self.scene / "scene.gltf"]

    def frames(self, out="shot"):
        return [self.tmp / f"{out}.{n:04d}.exr" for n in range(4)]

    def test_shot(self):
        s = summary(farm("frames", "0-3", "--workers", 2, *self.shot_args()))
        self.assertEqual((s["tasks"], s["rendered"], s["skipped"], s["failed"]), (4, 4, 0, 0))
        self.assertIn("commit", s["osr_vk"])
        for f in self.frames():
            exr_file.check_complete(f, 64, 64, ["R", "direct.R", "depth.Z"])
        # Frame n is camera n, as osr-vk renders it alone.
        one = self.tmp / "one.exr"
        subprocess.run([OSR_VK, *SHOT, "--camera", "2", "--quiet", "--offline", one, self.scene / "scene.gltf"],
                       check=True)
        self.assertTrue(all((layers(self.frames()[2])[c] == v).all() for c, v in layers(one).items()))
        self.assertFalse((layers(self.frames()[0])["R"] == layers(self.frames()[1])["R"]).all())
        # An animated glTF: frame N is osr-vk --frames N-N, the frames osr-vk renders alone
        # (without temporal reuse).
        path = ROOT / "tests" / "data" / "scene" / "camera_path.gltf"
        s = summary(farm("frames", "2-3", "--workers", 2, "--osr-vk", OSR_VK, "--", *SHOT,
                         "--offline", self.tmp / "walk_##.exr", path))
        self.assertEqual(s["rendered"], 2)
        subprocess.run([OSR_VK, *SHOT, "--frames", "2-3", "--temporal-reuse", "0", "--quiet", "--offline",
                        self.tmp / "alone_##.exr", path], check=True)
        for n in (2, 3):
            farmed, alone = layers(self.tmp / f"walk_0{n}.exr"), layers(self.tmp / f"alone_0{n}.exr")
            self.assertTrue(all((farmed[c] == v).all() for c, v in alone.items()), f"frame {n}")
        self.assertFalse((layers(self.tmp / "walk_02.exr")["R"] == layers(self.tmp / "walk_03.exr")["R"]).all())
        # Resumed: a frame deleted and a frame cut short render again; the others stand.
        self.frames()[2].unlink()
        data = self.frames()[1].read_bytes()
        self.frames()[1].write_bytes(data[:len(data) // 2])
        kept = {f: f.stat().st_mtime_ns for f in (self.frames()[0], self.frames()[3])}
        s = summary(farm("frames", "0-3", "--workers", 2, *self.shot_args()))
        self.assertEqual((s["rendered"], s["skipped"]), (2, 2))
        self.assertEqual(sorted(r["task"] for r in s["task_results"]), ["frame 1", "frame 2"])
        for f, t in kept.items():
            self.assertEqual(f.stat().st_mtime_ns, t, f"{f} was rendered again")
        for f in self.frames():
            exr_file.check_complete(f, 64, 64)

    def test_kill(self):
        # Longer frames, so that one is surely running when its worker is killed.
        args = ["frames", "0-3", "--workers", 2, "--osr-vk", OSR_VK, "--", "--mode", "path", "--spp", "12",
                "--width", "64", "--height", "64", "--offline", self.tmp / "shot.exr", self.scene / "scene.gltf"]
        p = subprocess.Popen([PY, str(TOOLS / "osr_farm.py"), *map(str, args)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        killed = None
        deadline = time.monotonic() + 120
        while killed is None and time.monotonic() < deadline and p.poll() is None:
            for proc in Path("/proc").iterdir():
                try:
                    cmd = (proc / "cmdline").read_bytes().split(b"\0")
                    if cmd[0].endswith(b"osr-vk") and str(self.tmp).encode() in b" ".join(cmd) \
                            and b"--camera" in cmd and cmd[cmd.index(b"--camera") + 1] == b"1":
                        worker = int((proc / "stat").read_text().rsplit(")", 1)[1].split()[1])
                        os.kill(worker, signal.SIGKILL)
                        killed = worker
                        break
                except (OSError, ValueError, IndexError):
                    continue
            time.sleep(0.05)
        out, err = p.communicate(timeout=300)
        self.assertIsNotNone(killed, "never saw frame 1 running")
        self.assertEqual(p.returncode, 0, err[-2000:])
        s = json.loads(out)
        self.assertEqual((s["rendered"], s["failed"]), (4, 0))
        self.assertGreaterEqual(s["retried"], 1, err[-2000:])
        for f in self.frames():
            exr_file.check_complete(f, 64, 64)
        self.assertFalse(list(self.tmp.glob("*.tmp*")), "a temporary file was left")

    def test_tiles(self):
        # Path: the assembled image is the single render, every layer, bit for bit. Tiles are
        # not denoised by default (osr-vk --help, --filter), so neither is the single render.
        path = ["--mode", "path", "--spp", "4", "--seed", "5", "--width", "128", "--height", "96"]
        s = summary(farm("tiles", "2x2", "--workers", 2, "--osr-vk", OSR_VK, "--", *path,
                         "--offline", self.tmp / "tiled.exr", CORNELL))
        self.assertEqual((s["tasks"], s["margin"]), (4, 0))
        subprocess.run([OSR_VK, *path, "--network", "none", "--filter", "none", "--quiet", "--offline", self.tmp / "one.exr", CORNELL],
                       check=True)
        tiled, one = layers(self.tmp / "tiled.exr"), layers(self.tmp / "one.exr")
        self.assertEqual(sorted(tiled), sorted(one))
        for c in one:
            self.assertTrue((tiled[c] == one[c]).all(), c)
        r = subprocess.run([OSR_VK, "compare", self.tmp / "tiled.exr", self.tmp / "one.exr"],
                           capture_output=True, text=True, check=True)
        self.assertEqual(json.loads(r.stdout)["relmse"], 0)
        # OSR: within the noise of two single renders, and no more error along the tile borders.
        osr = ["--mode", "osr", "--passes", "2", "--width", "128", "--height", "128"]
        s = summary(farm("tiles", "2x2", "--workers", 2, "--osr-vk", OSR_VK, "--", *osr, "--seed", "1",
                         "--offline", self.tmp / "osr_tiled.exr", CORNELL))
        self.assertEqual(s["margin"], 32)
        for seed in ("1", "2"):
            subprocess.run([OSR_VK, *osr, "--seed", seed, "--filter", "none", "--quiet", "--offline", self.tmp / f"osr{seed}.exr",
                            CORNELL], check=True)

        tiled, a, b = (exr_file.read_rgb(self.tmp / n) for n in ("osr_tiled.exr", "osr1.exr", "osr2.exr"))
        mask = tile_seams.seam_mask(128, 128, 2, 2, 2)
        err, noise = tile_seams.errors(tiled, a, mask), tile_seams.errors(b, a, mask)
        print("osr tiles vs one render:", err, "two renders:", noise, file=sys.stderr)
        self.assertLess(err["rest_relmse"], 2.0 * noise["rest_relmse"] + 1e-4, (err, noise))
        self.assertLess(err["seam_relmse"], 2.0 * noise["seam_relmse"] + 1e-4, (err, noise))
        # The same seed draws the same pixel streams: the tiles differ from the single render
        # only by their maps (the grid starts at each crop), and no more along the borders.
        self.assertLess(err["seam_relmse"], 2.0 * err["rest_relmse"] + 1e-5, err)

    def refused(self, r, needle):
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertIn(needle, r.stderr)
        self.assertNotIn("Traceback", r.stderr)

    def test_bad(self):
        out = self.tmp / "keep.exr"
        out.write_bytes(b"not overwritten")
        job = ["--", *SHOT, "--offline", out, CORNELL]
        self.refused(farm("frames", "0-3", "--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", 3,
                          "--osr-vk", OSR_VK, *job, check=False), "cannot reach the scheduler tcp://127.0.0.1:9")
        self.refused(farm("tiles", "64x1", "--workers", 1, "--osr-vk", OSR_VK, *job, check=False),
                     "tiles: 64x1 tiles of the 64x64 image are 1 px across")
        self.refused(farm("frames", "3-1", "--osr-vk", OSR_VK, *job, check=False), "not a range")
        # A cluster of two workers, one of which runs another osr-vk build; then a scene only
        # this machine has (here: none has).
        sched = self.tmp / "scheduler.json"
        fake = self.tmp / "osr-vk"
        fake.write_text(f"#!/bin/sh\nif [ -n \"$OSR_FARM_TEST_OLD\" ] && [ \"$1\" = --version ]; then\n"
                        f"  echo 'osr-vk 0.0.9 (commit 0000000, packed weights format 1)'; exit 0\nfi\n"
                        f"exec {OSR_VK} \"$@\"\n")
        fake.chmod(0o755)
        procs = [subprocess.Popen([PY, "-m", "distributed.cli.dask_scheduler", "--scheduler-file", sched,
                                   "--host", "127.0.0.1", "--port", "0", "--dashboard-address", ":0"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
        try:
            for i in range(2):
                env = dict(os.environ, **({"OSR_FARM_TEST_OLD": "1"} if i else {}))
                procs.append(subprocess.Popen([PY, "-m", "distributed.cli.dask_worker", "--scheduler-file", sched,
                                               "--nthreads", "1", "--no-nanny"], env=env,
                                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            deadline = time.monotonic() + 120  # the cluster up: its file written, both workers in
            while not sched.is_file() and time.monotonic() < deadline:
                time.sleep(0.2)
            from distributed import Client
            with Client(scheduler_file=str(sched), timeout=60) as c:
                c.wait_for_workers(2, timeout=120)
            r = farm("frames", "0-0", "--scheduler-file", sched, "--osr-vk", fake, *job, check=False)
            self.refused(r, "osr-vk 0.0.9 (commit 0000000")
            self.assertIn("not this build's osr-vk", r.stderr)
            r = farm("frames", "0-0", "--scheduler-file", sched, "--osr-vk", OSR_VK, "--", *SHOT,
                     "--offline", out, self.tmp / "elsewhere.gltf", check=False)
            self.refused(r, f"{self.tmp / 'elsewhere.gltf'}: no such file")
            self.assertIn("worker tcp://", r.stderr)
        finally:
            # Shutting down is not under test: a Dask process that does not leave within 30 s
            # of SIGTERM on a loaded machine is killed rather than failing the test.
            for p in procs:
                p.terminate()
            for p in procs:
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait(timeout=30)
        self.assertEqual(out.read_bytes(), b"not overwritten")
        self.assertFalse((self.tmp / "keep.0000.exr").exists())


if __name__ == "__main__":
    case = sys.argv.pop(1) if len(sys.argv) > 1 else None
    unittest.main(defaultTest=f"Farm.test_{case}" if case else None, verbosity=2)
