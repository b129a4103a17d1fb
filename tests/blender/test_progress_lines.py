#!/usr/bin/env python3
"""The add-on's reading of osr-vk's output (blender/osr_vk/process.py, no Blender needed):
progress lines as osr-vk prints them and reworded ones, lines that are not progress, and a
real osr-vk run through a pseudo-terminal with its lines streamed and the exit code returned.

usage: test_progress_lines.py [OSR_VK SCENE]
"""
import importlib.util
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location(
    "osr_vk_process", os.path.join(HERE, "..", "..", "blender", "osr_vk", "process.py"))
process = importlib.util.module_from_spec(spec)
spec.loader.exec_module(process)


def check(condition, what):
    if not condition:
        raise AssertionError(what)


def main() -> int:
    p = process.parse_progress("osr-vk: 12/64 spp, 3.1 s elapsed, ~13.2 s remaining")
    check(p and (p.done, p.total, p.unit) == (12, 64, "spp"), "the current line")
    check(abs(p.fraction() - max(12 / 64, 3.1 / 16.3)) < 1e-9, "fraction %g" % p.fraction())
    # --time alone: a huge unit target, progress from the clock.
    p = process.parse_progress("osr-vk: 40/16777216 passes, 5.0 s elapsed, ~15.0 s remaining")
    check(p and abs(p.fraction() - 0.25) < 1e-9, "time-limited fraction")
    # --time alone: no "/M" at all.
    p = process.parse_progress("osr-vk: 7 passes, 3.0 s elapsed, ~1.0 s remaining")
    check(p and (p.done, p.total, p.unit) == (7, 0, "passes"), "time-only line")
    check(abs(p.fraction() - 0.75) < 1e-9, "time-only fraction %g" % p.fraction())
    # A unit in slices: its share counts.
    p = process.parse_progress("osr-vk: 0/2 passes (+40% of the next), 8.0 s elapsed, ~50.0 s remaining")
    check(p and (p.done, p.total, p.partial) == (0, 2, 0.4), "partial unit")
    check(abs(p.fraction() - 0.2) < 1e-9, "partial fraction %g" % p.fraction())
    # Reworded lines keep working as long as they say N/M.
    p = process.parse_progress("osr-vk: pass 3 / 32 (2.0 s elapsed)")
    check(p and (p.done, p.total) == (3, 32) and p.remaining_s is None, "reworded line")
    check(abs(p.fraction() - 3 / 32) < 1e-9, "fraction without remaining time")
    # An animation render announces each frame; that N/M counts frames, not progress units.
    check(process.parse_frame("osr-vk: frame 2/48 (frame 1 at 0.042 s)") == (2, 48), "frame line")
    check(process.parse_frame("osr-vk: 1/4 spp, 0.1 s elapsed, ~0.3 s remaining") is None,
          "a progress line is no frame line")
    for line in ["osr-vk: frame 2/48 (frame 1 at 0.042 s)",
                 "osr-vk: frame 1/4 (frame 0): shot_0000.exr complete, skipped (--resume)",
                 "osr-vk: 4 frames in 2.10 s, 1 skipped (--resume)",
                 "osr-vk: 96x72, 16 spp in 0.63 s, pt_trace 625 ms",
                 "osr-vk: warning: scene.gltf: unsupported extension KHR_x ignored",
                 "osr-vk: scene.gltf: camera 1/2 error", "something 1/2 else"]:
        check(process.parse_progress(line) is None, "not progress: %r" % line)

    if len(sys.argv) == 3:
        exe, scene = sys.argv[1:]
        with tempfile.TemporaryDirectory() as work:
            lines = []
            code, tail = process.run([exe, "--offline", os.path.join(work, "a.exr"), "--mode", "path",
                                      "--spp", "8", "--width", "32", "--height", "32", scene],
                                     lines.append, lambda: False)
            progress = [l for l in lines if process.parse_progress(l)]
            check(code == 0, "osr-vk exited %d: %s" % (code, tail))
            check(progress and process.parse_progress(progress[-1]).fraction() == 1.0,
                  "no final progress line in %s" % lines)
            check(not any("\r" in l for l in lines), "carriage returns left in lines")
            check(not any("validation" in l for l in lines), "validation messages: %s" % lines)
            code, tail = process.run([exe, "--offline", os.path.join(work, "b.exr"),
                                      os.path.join(work, "missing.gltf")], lines.append, lambda: False)
            check(code == 2 and "missing.gltf" in tail[-1], "a failing run: %d %s" % (code, tail))
            print("osr-vk run: %d lines, %d progress lines" % (len(lines), len(progress)))
    print("progress lines: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
