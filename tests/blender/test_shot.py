#!/usr/bin/env python3
"""The add-on's Render Animation in one osr-vk run (blender/osr_vk/shot.py, no Blender needed):
which osr-vk frames and --fps serve Blender's frames, and a real `osr-vk --frames` run served
frame by frame from one process, cancelled (osr-vk terminated and reaped) and failing (the
exit code and osr-vk's error line).

usage: test_shot.py OSR_VK SCENE   (SCENE: a glTF with an animation)
"""
import importlib
import os
import sys
import tempfile
import time
import types

HERE = os.path.dirname(os.path.abspath(__file__))
# The add-on's modules without its __init__.py, which needs Blender.
package = types.ModuleType("osr_vk_pure")
package.__path__ = [os.path.join(HERE, "..", "..", "blender", "osr_vk")]
sys.modules["osr_vk_pure"] = package
shot = importlib.import_module("osr_vk_pure.shot")
process = importlib.import_module("osr_vk_pure.process")


def check(condition, what):
    if not condition:
        raise AssertionError(what)


def check_plans():
    # Blender's exporter writes frame f at f / fps s; osr-vk's frame k is at k / fps' s.
    p = shot.plan(3, 6, 1, 24)
    check(p.frames == [3, 4, 5, 6] and p.args() == ["--frames", "3-6", "--fps", "24.0"],
          "step 1: %s %s" % (p.frames, p.args()))
    check([p.osr_frame(f) for f in p.frames] == [3, 4, 5, 6], "step 1 numbers")
    p = shot.plan(4, 9, 2, 24)  # frames 4, 6, 8 at 4/24, 6/24, 8/24 s = 2, 3, 4 at 12 fps
    check(p.frames == [4, 6, 8] and p.args() == ["--frames", "2-4", "--fps", "12.0"],
          "step 2: %s %s" % (p.frames, p.args()))
    for k, f in enumerate(p.frames, start=2):
        check(abs(k / 12.0 - f / 24.0) < 1e-12 and p.osr_frame(f) == k, "step 2 time of %d" % f)
    check(isinstance(shot.plan(1, 9, 2, 24), str), "a step that does not divide the first frame")
    check(isinstance(shot.plan(0, 2000000, 1, 24), str), "frames beyond osr-vk's six digits")


def gone(pid):
    return not os.path.exists("/proc/%d" % pid)


def main() -> int:
    check_plans()
    exe, scene = sys.argv[1:3]
    with tempfile.TemporaryDirectory() as work:
        pattern, fmt = shot.frame_pattern(work, ".exr")
        plan = shot.plan(3, 6, 1, 24)
        base = [exe, "--offline", pattern, "--mode", "path", "--width", "32", "--height", "24"]
        s = shot.Shot(base + ["--spp", "2"] + plan.args() + [scene], plan, fmt, work, False,
                      os.path.join(work, "log.txt"))
        lines, start = [], time.monotonic()
        for f in plan.frames:
            check(s.serves(f), "frame %d not served" % f)
            path = s.wait(f, lines.append, lambda: False)
            check(path == os.path.join(work, "frame_%06d.exr" % f) and os.path.isfile(path), path)
            check(not s.serves(f), "frame %d served twice" % f)
        code = s.finish(lines.append, lambda: False)
        check(code == 0, "osr-vk exited %d: %s" % (code, s.child.tail))
        announced = [process.parse_frame(l) for l in lines if process.parse_frame(l)]
        check(announced == [(1, 4), (2, 4), (3, 4), (4, 4)] and s.announced == (4, 4),
              "frame lines %s, last %s" % (announced, s.announced))
        check(gone(s.child.pid), "osr-vk still running after finish")
        with open(os.path.join(work, "log.txt")) as f:
            check(f.read().count("osr-vk: frame ") == 4, "the log misses frame lines")
        check(not any("validation" in l for l in lines), "validation messages: %s" % lines)
        print("shot: 4 frames from one osr-vk (pid %d) in %.1f s" % (s.child.pid, time.monotonic() - start))

        # Cancel while a frame renders: osr-vk is terminated and reaped.
        s = shot.Shot(base + ["--spp", "1000000", "--time", "60"] + plan.args() + [scene],
                      plan, os.path.join(work, "c_%06d.exr"), work, False)
        deadline = time.monotonic() + 2.0
        try:
            s.wait(3, lambda line: None, lambda: time.monotonic() > deadline)
            raise AssertionError("not cancelled")
        except process.Cancelled:
            pass
        check(s.child.proc.returncode is not None and gone(s.child.pid), "osr-vk left behind")
        check(time.monotonic() - deadline < 10, "cancel took %.1f s" % (time.monotonic() - deadline))

        # osr-vk fails (no such scene): Failed with its exit code and error line.
        missing = os.path.join(work, "missing.gltf")
        s = shot.Shot(base + plan.args() + [missing], plan, os.path.join(work, "m_%06d.exr"), work, False)
        try:
            s.wait(3, lambda line: None, lambda: False)
            raise AssertionError("no failure")
        except shot.Failed as e:
            check(e.code == 2 and any("missing.gltf" in l for l in e.tail), "failure %s %s" % (e.code, e.tail))
        check(gone(s.child.pid), "failed osr-vk not reaped")
    print("shot: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
