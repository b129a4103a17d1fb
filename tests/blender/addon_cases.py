# Run inside headless Blender by tests/blender/test_blender_addon.py:
#   blender -b --factory-startup --python-exit-code 1 --python addon_cases.py -- CASE OSR_VK WORK
# CASE render: renders the test scene with the osr-vk engine (path tracing, fixed samples and
#   seed, files kept in WORK/keep) and saves the result as WORK/blender.exr (Combined, RGBA)
#   and WORK/blender_layers.exr (every pass, multi-layer).
# CASE cancel: starts a long render, interrupts Blender as Ctrl-C does once osr-vk runs, and
#   checks the osr-vk child is gone (terminated and reaped) when the render returns.
# CASE missing: an executable path that does not exist: the render must fail with a report.
# CASE install: installs ZIP (the 4th argument, CMake's osr_vk.zip) with Blender's add-on
#   installer and renders with the osr-vk bundled in it.
# CASE f12 (Blender's UI, under xvfb-run): an interactive F12 render, compared as in render.
# CASE border: resolution percentage, render region and two view layers.
# CASE world: the world colour and image as --env files (export only).
# CASE cycles: the area light's direct light against Cycles' (light units).
# CASE animation: Render Animation of a shot (camera and sphere moving) through one osr-vk
#   --frames run, each frame compared with osr-vk run by hand on its single-frame export.
# CASE animation_cancel: Ctrl-C during the shot's second frame: osr-vk gone, no more frames.
# CASE animation_fallback: a keyed material colour: frame by frame, a fresh export per frame,
#   frame 2 compared with osr-vk run by hand on its export.
# CASE animation_timing (not a test): seconds per frame in one run and frame by frame.
# CASE materials: Principled BSDF materials the exporter must keep for osr-vk: a colour
#   attribute feeding Base Color (COLOR_0 kept) and one no material reads (dropped), alpha
#   blending, an emission texture with strength, a texture on the second UV map (TEXCOORD_1).
# CASE failed: osr-vk exits with an error (a weights file that is not there): a report naming it;
#   a scene with nothing to render and one whose only mesh has no faces: reports that name no
#   temporary file.
# Failures raise (the exit code is 1); the driver checks the rest from the output.
import json
import math
import os
import signal
import subprocess
import sys
import threading
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_scene  # noqa: E402


def _load_exr_module():
    # The add-on's EXR reader, loaded from its file: importing the osr_vk package here would
    # shadow the installed add-on in the install case.
    import importlib.util
    path = os.path.join(blender_scene.REPO, "blender", "osr_vk", "exr.py")
    spec = importlib.util.spec_from_file_location("osr_vk_test_exr", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


exr = _load_exr_module()

SEED, SAMPLES, WIDTH, HEIGHT = 7, 16, 96, 72
# Same seed, settings and device: osr-vk's path tracer is deterministic, so Blender's image
# must equal the hand-run one but for float rounding in the EXR round trips.
RELMSE_TOLERANCE = 1e-6


def save(path, fmt):
    settings = bpy.context.scene.render.image_settings
    settings.file_format, settings.color_depth = fmt, "32"
    bpy.data.images["Render Result"].save_render(path)


def _layers(path):
    _, _, planes = exr.read_layers(path)
    return planes


def _relmse(a, b, eps=0.01):
    return float(np.mean((a - b) ** 2 / (b * b + eps)))


def _reference(executable, gltf, env, out, spp=SAMPLES, width=WIDTH, height=HEIGHT):
    """osr-vk run by hand on `gltf` with the test's settings, into `out`."""
    run = subprocess.run(
        [executable, "--offline", out, "--exr-float", "--quiet", "--mode", "path", "--spp",
         str(spp), "--seed", str(SEED), "--width", str(width), "--height", str(height)]
        + (["--env", env] if env else []) + [gltf], check=True, capture_output=True, text=True)
    if "validation" in run.stderr:
        raise AssertionError("osr-vk reported validation messages:\n" + run.stderr)
    return out


def _compare(executable, test, ref):
    out = subprocess.run([executable, "compare", test, ref], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)["relmse"]


def check_against_reference(executable, work, keep, mine):
    """Runs osr-vk by hand on the glTF the add-on exported, with the test's settings, and
    compares Blender's saved result `mine` with it. Returns the reference EXR's path."""
    with open(os.path.join(keep, "osr-vk.log")) as f:
        log = f.read()
    if "validation" in log:
        raise AssertionError("osr-vk reported validation messages:\n" + log)
    env = os.path.join(keep, "world.exr")
    ref = _reference(executable, os.path.join(keep, "scene.gltf"), env if os.path.isfile(env) else None,
                     os.path.join(work, "reference.exr"))
    relmse = _compare(executable, mine, ref)
    print("osr-vk test: Blender's result against osr-vk --offline: relMSE %g (tolerance %g)"
          % (relmse, RELMSE_TOLERANCE))
    if not relmse <= RELMSE_TOLERANCE:
        raise AssertionError("relMSE %g over %g" % (relmse, RELMSE_TOLERANCE))
    return ref


def case_render(executable, work):
    scene = blender_scene.build_scene(executable, WIDTH, HEIGHT)
    scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.seed = "path", SAMPLES, SEED
    scene.osr_vk.keep_directory = keep = os.path.join(work, "keep")
    scene.world.color = (0.02, 0.03, 0.05)  # a world colour: handed over as --env world.exr
    start = time.monotonic()
    bpy.ops.render.render()
    print("osr-vk test: render in Blender took %.2f s" % (time.monotonic() - start))
    mine = os.path.join(work, "blender.exr")
    save(mine, "OPEN_EXR")
    save(os.path.join(work, "blender_layers.exr"), "OPEN_EXR_MULTILAYER")
    ref = check_against_reference(executable, work, keep, mine)
    if "--env" not in open(os.path.join(keep, "command.txt")).read():
        raise AssertionError("the world colour was not handed over as --env")

    # Passes: in Blender's multi-layer EXR, each equal to osr-vk's layer (normals turned to +Z up).
    got, want = _layers(os.path.join(work, "blender_layers.exr")), _layers(ref)
    checks = {"Direct": ("direct.R", "direct.G", "direct.B"),
              "Indirect": ("indirect.R", "indirect.G", "indirect.B"),
              "Albedo": ("albedo.R", "albedo.G", "albedo.B"),
              "Normal": ("normal.X", "-normal.Z", "normal.Y"), "Depth": ("depth.Z",)}
    for name, sources in checks.items():
        ids = "Z" if name == "Depth" else ("XYZ" if name == "Normal" else "RGB")
        for cid, src in zip(ids, sources):
            key = "ViewLayer.%s.%s" % (name, cid)
            if key not in got:
                raise AssertionError("pass %s missing from the render result (%s)" % (key, sorted(got)))
            expect = -want[src[1:]] if src.startswith("-") else want[src]
            if name == "Depth":  # nothing hit: 0 in osr-vk, 1e10 in Blender
                expect = np.where(expect > 0, expect, 1e10)
            bad = np.abs(got[key] - expect) > 1e-5 * np.maximum(1.0, np.abs(expect))
            if bad.any():
                raise AssertionError("pass %s differs from osr-vk's %s at %d pixels"
                                     % (key, src, int(bad.sum())))
    # Not black, not mirrored: the red wall is on the left, the green one on the right.
    r, g = got["ViewLayer.Combined.R"], got["ViewLayer.Combined.G"]
    third = WIDTH // 3
    if not (r.mean() > 0.05 and r[:, :third].mean() > g[:, :third].mean()
            and g[:, -third:].mean() > r[:, -third:].mean()):
        raise AssertionError("the image is black or mirrored")
    up = got["ViewLayer.Normal.Z"][HEIGHT - 3, WIDTH // 2]  # floor near the bottom centre
    if not up > 0.9:
        raise AssertionError("the floor's normal is %g along +Z, expected 1" % up)


class _Watch:
    """Pids of this process's osr-vk children seen while the block runs (polled every 20 ms:
    each osr-vk run of the add-on lasts a second or more on lavapipe)."""

    def __enter__(self):
        self.pids, self._stop = set(), threading.Event()

        def poll():
            while not self._stop.wait(0.02):
                self.pids.update(pid for pid, _ in _children("osr-vk"))
        self._thread = threading.Thread(target=poll)
        self._thread.start()
        return self

    def __exit__(self, *_):
        self._stop.set()
        self._thread.join()


# A shot: the camera on a rig (an empty) that rises and turns, and the sphere crossing the
# room, keyed (Bezier) a frame before the first and after the last frame rendered, from 2 to
# 5: frame f of the glTF is at f / fps s, so a shot read from 0 would show frame 1's pose first.
SHOT_FIRST, SHOT_LAST, SHOT_SIZE, SHOT_SPP = 2, 5, (64, 48), 8


def _animated_scene(executable, work, first=SHOT_FIRST, last=SHOT_LAST, size=SHOT_SIZE, spp=SHOT_SPP):
    return _animate(blender_scene.build_scene(executable, *size), work, first, last, spp)


def _animate(scene, work, first=SHOT_FIRST, last=SHOT_LAST, spp=SHOT_SPP):
    scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.seed = "path", spp, SEED
    # Each frame as F12 renders it, so that the frames line up with single renders.
    scene.osr_vk.temporal_reuse = 0.0
    scene.osr_vk.keep_directory = os.path.join(work, "keep")
    sphere = bpy.data.objects["sphere"]
    for frame, x in ((first - 1, -1.2), (last + 1, 1.2)):
        sphere.location.x = x
        sphere.keyframe_insert("location", frame=frame)
    rig = bpy.data.objects.new("rig", None)
    scene.collection.objects.link(rig)
    scene.camera.parent = rig
    for frame, z, turn in ((first - 1, 0.0, -0.15), (last + 1, 0.5, 0.15)):
        rig.location.z, rig.rotation_euler.z = z, turn
        rig.keyframe_insert("location", frame=frame)
        rig.keyframe_insert("rotation_euler", frame=frame)
    scene.frame_start, scene.frame_end = first, last
    scene.render.filepath = os.path.join(work, "frame_")
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    return scene


def case_animation(executable, work):
    """Render Animation through one osr-vk --frames run: one process for the shot, and each
    frame equal to osr-vk run by hand on the add-on's single-frame export of that frame (the
    F12 path), but not to its neighbours' (the frame numbers line up)."""
    scene = _animated_scene(executable, work)
    frames = list(range(SHOT_FIRST, SHOT_LAST + 1))
    start = time.monotonic()
    with _Watch() as watch:
        bpy.ops.render.render(animation=True)
    took = time.monotonic() - start
    print("osr-vk test: Render Animation of %d frames took %.2f s (%.2f s a frame), osr-vk pids %s"
          % (len(frames), took, took / len(frames), sorted(watch.pids)))
    keep = scene.osr_vk.keep_directory
    command = open(os.path.join(keep, "command.txt")).read()
    if "--frames %d-%d --fps 24.0 --temporal-reuse 0" % (SHOT_FIRST, SHOT_LAST) not in command:
        raise AssertionError("not one osr-vk --frames run with the add-on's reuse: %s" % command)
    if len(watch.pids) != 1:
        raise AssertionError("%d osr-vk processes for the shot, expected 1" % len(watch.pids))
    if _children("osr-vk"):
        raise AssertionError("osr-vk left running after the shot")
    _check_shot_frames(executable, work, scene)
    _check_still_shot(executable, work)


def _check_shot_frames(executable, work, scene):
    """Each frame of the shot against osr-vk on the add-on's single-frame export of it, and
    of the frames before and after it."""
    frames = list(range(SHOT_FIRST, SHOT_LAST + 1))
    from osr_vk import export
    refs = {}
    for f in [SHOT_FIRST - 1] + frames + [SHOT_LAST + 1]:  # one frame beyond each end too
        scene.frame_set(f)
        directory = os.path.join(work, "single_%d" % f)
        os.makedirs(directory)
        single = export.export(bpy.context.evaluated_depsgraph_get(), directory)
        refs[f] = _reference(executable, single.gltf_path, single.env_path,
                             os.path.join(directory, "reference.exr"), SHOT_SPP, *SHOT_SIZE)
    for f in frames:
        mine = os.path.join(work, "frame_%04d.exr" % f)
        if not os.path.isfile(mine):
            raise AssertionError("Render Animation wrote no %s" % mine)
        same = _compare(executable, mine, refs[f])
        before, after = _compare(executable, mine, refs[f - 1]), _compare(executable, mine, refs[f + 1])
        print("osr-vk test: frame %d against osr-vk on its own export: relMSE %g; on frame %d's "
              "%g, on frame %d's %g" % (f, same, f - 1, before, f + 1, after))
        if not same <= RELMSE_TOLERANCE:
            raise AssertionError("frame %d: relMSE %g over %g" % (f, same, RELMSE_TOLERANCE))
        if not min(before, after) > 100 * max(same, 1e-6):
            raise AssertionError("frame %d is as close to a neighbour's pose as to its own" % f)
    print("osr-vk test: %d frames from one osr-vk run, each its own frame" % len(frames))


def _check_still_shot(executable, work):
    """Render Animation of a scene where nothing moves: one osr-vk --frames run (the export
    gets a one-key animation), every frame the same image."""
    scene = blender_scene.build_scene(executable, *SHOT_SIZE)
    scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.seed = "path", SHOT_SPP, SEED
    scene.osr_vk.temporal_reuse = 0.0  # with it, the second frame adds up the first's samples
    scene.frame_start, scene.frame_end = 1, 2
    scene.render.filepath = os.path.join(work, "still_")
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    with _Watch() as watch:
        bpy.ops.render.render(animation=True)
    a, b = (_layers(os.path.join(work, "still_%04d.exr" % f)) for f in (1, 2))
    print("osr-vk test: still shot, osr-vk pids %s" % sorted(watch.pids))
    if len(watch.pids) != 1 or not all(np.array_equal(a[c], b[c]) for c in "RGB"):
        raise AssertionError("a still shot: %d osr-vk runs, frames equal: %s"
                             % (len(watch.pids), all(np.array_equal(a[c], b[c]) for c in "RGB")))


def case_animation_cancel(executable, work):
    """Esc (here SIGINT, as Ctrl-C) while the second frame of a shot renders: osr-vk is
    terminated and reaped, Blender writes no further frame, and a render afterwards works."""
    scene = _animated_scene(executable, work, 1, 4)
    scene.osr_vk.samples, scene.osr_vk.time_limit = 1 << 20, 6.0  # 6 s a frame
    first = os.path.join(work, "frame_0001.exr")
    seen, interrupted = [], []

    def interrupt():
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not os.path.isfile(first):
            seen.extend(p for p in _children("osr-vk") if p not in seen)
            time.sleep(0.05)
        time.sleep(1.5)  # frame 2 is under way
        seen.extend(p for p in _children("osr-vk") if p not in seen)
        interrupted.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    thread = threading.Thread(target=interrupt)
    thread.start()
    start = time.monotonic()
    try:
        bpy.ops.render.render(animation=True)
    except RuntimeError as e:
        print("osr-vk test: render raised %s" % e)
    end = time.monotonic()
    thread.join()
    left = _children("osr-vk")
    pids = sorted({pid for pid, _ in seen})
    print("osr-vk test: shot interrupted after %.2f s, render returned %.2f s later; osr-vk pid "
          "%s; children left: %s" % (interrupted[0] - start, end - interrupted[0],
                                     " ".join(map(str, pids)), left))
    if end - interrupted[0] > 10:  # osr-vk stops at its next check, else is killed at 5 s
        raise AssertionError("cancel took %.1f s" % (end - interrupted[0]))
    if not os.path.isfile(first):
        raise AssertionError("frame 1 was not written before the cancel")
    if len(pids) != 1:
        raise AssertionError("osr-vk processes %s, expected one for the shot" % pids)
    if left:
        raise AssertionError("osr-vk left behind after cancel: %s" % left)
    written = sorted(f for f in os.listdir(work) if f.startswith("frame_"))
    if written != ["frame_0001.exr"]:
        raise AssertionError("frames written: %s" % written)
    scene.osr_vk.samples, scene.osr_vk.time_limit = 2, 0.0
    bpy.ops.render.render()
    print("osr-vk test: rendered again after the cancel")


def case_animation_fallback(executable, work):
    """Render Animation of what glTF cannot carry (here the sphere's keyed colour) goes frame
    by frame, each a fresh export of the frame being rendered: the sphere moves between frames
    1 and 2, the frames differ, and frame 2 equals osr-vk run by hand on the export of frame 2.
    (Before the add-on exported the current frame, both frames showed frame 0's pose.)"""
    scene = blender_scene.build_scene(executable, WIDTH, HEIGHT)
    scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.seed = "path", SAMPLES, SEED
    scene.osr_vk.keep_directory = keep = os.path.join(work, "keep")
    sphere = bpy.data.objects["sphere"]
    colour = sphere.data.materials[0].node_tree.nodes["Principled BSDF"].inputs["Base Color"]
    for frame, x in ((1, -0.8), (2, 0.8)):
        sphere.location.x = x
        sphere.keyframe_insert("location", frame=frame)
        colour.default_value = (0.9, 0.5 * frame, 0.3, 1.0)
        colour.keyframe_insert("default_value", frame=frame)
    scene.frame_start, scene.frame_end = 1, 2
    scene.render.filepath = os.path.join(work, "frame_")
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    with _Watch() as watch:
        bpy.ops.render.render(animation=True)
    if len(watch.pids) != 2:
        raise AssertionError("%d osr-vk runs for 2 frames, expected one each" % len(watch.pids))
    if "--frames" in open(os.path.join(keep, "command.txt")).read():
        raise AssertionError("rendered with --frames")
    frames = [os.path.join(work, "frame_%04d.exr" % f) for f in (1, 2)]
    for f in frames:
        if not os.path.isfile(f):
            raise AssertionError("Render Animation wrote no %s" % f)
    first, second = (_layers(f)["R"] for f in frames)
    moved = float(np.mean(np.abs(first - second)))
    print("osr-vk test: frame by frame (osr-vk pids %s); frames 1 and 2 differ by %g on "
          "average (red)" % (sorted(watch.pids), moved))
    if not moved > 1e-3:
        raise AssertionError("frames 1 and 2 are alike: the sphere did not move")
    check_against_reference(executable, work, keep, frames[1])


def case_animation_timing(executable, work):
    """Not a test (docs/blender.md quotes it): seconds per frame of Render Animation in one
    osr-vk run and frame by frame (One run per animation off), 8 frames at 96 x 72 and 16 spp
    of the shot of case animation (camera and sphere moving) and of its camera alone, each
    twice, alternating. Wall time, and CPU time of Blender and its osr-vk children (less
    dependent on other jobs on shared cores)."""
    for shot in ("camera and sphere", "camera only"):
        for repeat in range(2):
            for one_run in (True, False):
                name = "%s_%d_%d" % (shot.split()[-1], repeat, one_run)
                scene = _animated_scene(executable, os.path.join(work, name), 1, 8, (WIDTH, HEIGHT), SAMPLES)
                if shot == "camera only":
                    bpy.data.objects["sphere"].animation_data_clear()
                scene.osr_vk.one_run_per_animation = one_run
                scene.osr_vk.keep_directory = ""
                start, cpu = time.monotonic(), os.times()
                bpy.ops.render.render(animation=True)
                took, end = time.monotonic() - start, os.times()
                cpu_s = sum(end[:4]) - sum(cpu[:4])
                print("osr-vk test: %s, %s: 8 frames in %.1f s, %.2f s a frame (CPU %.2f s a frame)"
                      % (shot, "one osr-vk run" if one_run else "frame by frame", took, took / 8, cpu_s / 8))


def _children(name):
    """Pids of this process's live or unreaped children called `name` (from /proc)."""
    me, found = os.getpid(), []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                stat = f.read()
        except OSError:
            continue
        comm = stat[stat.index("(") + 1:stat.rindex(")")]
        fields = stat[stat.rindex(")") + 2:].split()
        if comm == name and int(fields[1]) == me:
            found.append((int(entry), fields[0]))
    return found


def case_cancel(executable, work):
    scene = blender_scene.build_scene(executable, WIDTH, HEIGHT)
    scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.time_limit = "path", 1 << 20, 120.0
    seen = []

    def interrupt():  # once osr-vk renders, what Ctrl-C in Blender's terminal does
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not seen:
            seen.extend(_children("osr-vk"))
            time.sleep(0.05)
        time.sleep(1.0)
        os.kill(os.getpid(), signal.SIGINT)

    thread = threading.Thread(target=interrupt)
    thread.start()
    start = time.monotonic()
    try:
        bpy.ops.render.render()
    except RuntimeError as e:
        print("osr-vk test: render raised %s" % e)
    took = time.monotonic() - start
    thread.join()
    if not seen:
        raise AssertionError("osr-vk never started")
    left = _children("osr-vk")
    print("osr-vk test: cancelled after %.2f s; osr-vk pid %d; children left: %s" % (took, seen[0][0], left))
    if left:
        raise AssertionError("osr-vk left behind after cancel: %s" % left)
    if took > 30:
        raise AssertionError("cancel took %.1f s" % took)
    # Blender still works: a second, short render completes.
    scene.osr_vk.samples, scene.osr_vk.time_limit = 2, 0.0
    bpy.ops.render.render()
    print("osr-vk test: rendered again after the cancel")


def _expect_report(accept, what, animation=False):
    """Renders, expecting a failure whose report `accept` (a function of its text) takes."""
    try:
        bpy.ops.render.render(animation=animation)
    except RuntimeError as e:
        print("osr-vk test: report: %s" % e)
        if not accept(str(e)):
            raise AssertionError("unexpected report: %s" % e)
        return
    raise AssertionError("%s reported no error" % what)


def case_missing(executable, work):
    blender_scene.build_scene(os.path.join(work, "no-such-dir", "osr-vk"), WIDTH, HEIGHT)
    _expect_report(lambda r: "osr-vk executable not found" in r, "a render without osr-vk")


def case_failed(executable, work):
    scene = blender_scene.build_scene(executable, WIDTH, HEIGHT)
    scene.osr_vk.mode, scene.osr_vk.weights = "osr", os.path.join(work, "missing.osrw")
    _expect_report(lambda r: "osr-vk failed (exit 2)" in r and "missing.osrw" in r,
                   "a failed osr-vk run")
    # Render Animation: the shot's one osr-vk run fails the same way; the error report ends
    # Render Animation (Blender stops at a frame that reports an error).
    scene.frame_start, scene.frame_end = 1, 3
    scene.render.filepath = os.path.join(work, "anim_")
    with _Watch() as watch:
        _expect_report(lambda r: "osr-vk failed (exit 2)" in r and "missing.osrw" in r,
                       "a failed shot", animation=True)
    written = [f for f in os.listdir(work) if f.startswith("anim_")]
    if len(watch.pids) > 1 or written:
        raise AssertionError("a failed shot: %d osr-vk runs, frames written %s" % (len(watch.pids), written))
    # Nothing renderable: the export says so.
    scene.osr_vk.weights = ""
    for obj in list(scene.objects):
        if obj.type != "CAMERA":
            bpy.data.objects.remove(obj, do_unlink=True)
    _expect_report(lambda r: "nothing to render" in r, "an empty scene")
    # A mesh without faces: osr-vk finds no triangles, and the report names no temporary file.
    empty = bpy.data.objects.new("no_faces", bpy.data.meshes.new("no_faces"))
    scene.collection.objects.link(empty)
    _expect_report(lambda r: "osr-vk failed (exit 2)" in r and "the exported scene" in r
                   and "scene.gltf" not in r, "a scene without triangles")


def case_install(executable, work, addon_zip):
    # Blender's own installer, into the user script directory the driver points elsewhere.
    bpy.ops.preferences.addon_install(filepath=addon_zip, overwrite=True)
    scene = blender_scene.build_scene("", WIDTH, HEIGHT, from_checkout=False)
    module = sys.modules["osr_vk"]
    installed = bpy.utils.user_resource("SCRIPTS", path="addons")
    if not os.path.abspath(module.__file__).startswith(os.path.abspath(installed)):
        raise AssertionError("osr_vk loaded from %s, not from %s" % (module.__file__, installed))
    from osr_vk import engine, process
    found = process.find_executable("", engine.ADDON_DIR)
    if found != os.path.join(engine.ADDON_DIR, "bin", "osr-vk"):
        raise AssertionError("the bundled osr-vk was not found (got %s)" % found)
    scene.osr_vk.mode, scene.osr_vk.samples = "path", 2
    bpy.ops.render.render()  # with the bundled osr-vk
    save(os.path.join(work, "installed.exr"), "OPEN_EXR")
    if not _layers(os.path.join(work, "installed.exr"))["R"].mean() > 0.05:
        raise AssertionError("the installed add-on rendered a black image")


def case_cycles(executable, work):
    # Units: the direct light of the area light, converted to an emissive polygon, against
    # Cycles' direct light (max_bounces 0) of the same Blender light. Both are noisy (osr-vk
    # 256 spp, Cycles 64): compared as mean radiance over the lit surfaces, 4 % apart at most
    # (measured 0.97-1.0 per wall; with P / (pi A) instead of P / (4 A) it is 1.27).
    scene = blender_scene.build_scene(executable, 80, 60)
    scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.seed = "path", 256, 1
    scene.osr_vk.keep_directory = keep = os.path.join(work, "keep")
    bpy.ops.render.render()
    ours = _layers(os.path.join(keep, "render.exr"))
    scene.render.engine = "CYCLES"
    scene.cycles.samples, scene.cycles.use_denoising, scene.cycles.max_bounces = 64, False, 0
    scene.cycles.sample_clamp_direct = 0.0
    scene.objects["ceiling light"].visible_camera = False
    # osr-vk's pixel filter: Cycles' Blackman-Harris at width 1 px (docs/pathtracer.md).
    scene.cycles.pixel_filter_type, scene.cycles.filter_width = "BLACKMAN_HARRIS", 1.0
    bpy.ops.render.render()
    path = os.path.join(work, "cycles_direct.exr")
    save(path, "OPEN_EXR")
    cycles = _layers(path)
    # The light panel itself (black albedo) is visible only in osr-vk's image: masked out with
    # a pixel's margin (its antialiased edge).
    panel = ours["albedo.G"] <= 0.01
    near = panel.copy()
    near[1:] |= panel[:-1]
    near[:-1] |= panel[1:]
    near[:, 1:] |= panel[:, :-1]
    near[:, :-1] |= panel[:, 1:]
    lit = ~near
    ratio = [float(ours["direct." + c][lit].mean() / cycles[c][lit].mean()) for c in "RGB"]
    print("osr-vk test: direct light, osr-vk / Cycles: R %.3f G %.3f B %.3f" % tuple(ratio))
    if not all(abs(r - 1.0) <= 0.04 for r in ratio):
        raise AssertionError("direct light differs from Cycles' by more than 4 %%: %s" % ratio)


def _image(name, path, pixels):
    image = bpy.data.images.new(name, 2, 1, alpha=True)
    image.pixels = [c for p in pixels for c in p]
    image.filepath_raw, image.file_format = path, "PNG"
    image.save()
    return image


def _color_attribute(mesh, colors):
    attr = mesh.color_attributes.new(name="Col", type="FLOAT_COLOR", domain="POINT")
    for i, v in enumerate(mesh.vertices):
        attr.data[i].color = colors(v.co)
    mesh.color_attributes.active_color = attr
    mesh.color_attributes.render_color_index = mesh.color_attributes.find("Col")


def case_materials(executable, work):
    blender_scene.build_scene(executable, 48, 36)
    # The sphere's Base Color is its colour attribute (red below, blue above).
    sphere = bpy.data.objects["sphere"]
    _color_attribute(sphere.data, lambda co: (1.0, 0.0, 0.0, 1.0) if co.z < 0 else (0.0, 0.0, 1.0, 1.0))
    mat = sphere.data.materials[0]
    attr_node = mat.node_tree.nodes.new("ShaderNodeVertexColor")
    attr_node.layer_name = "Col"
    mat.node_tree.links.new(attr_node.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    # The floor has a colour attribute its material does not read.
    _color_attribute(bpy.data.objects["floor"].data, lambda co: (0.0, 1.0, 0.0, 1.0))
    # A half-transparent curtain (alpha blend).
    bpy.ops.mesh.primitive_plane_add(size=1.5, location=(-0.8, 0.5, 1.2), rotation=(math.pi / 2, 0, 0))
    curtain = bpy.context.active_object
    curtain.name = "curtain"
    mat = bpy.data.materials.new("curtain")
    mat.use_nodes, mat.blend_method = True, "BLEND"
    mat.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 0.5
    curtain.data.materials.append(mat)
    # A screen: emission from a texture at strength 3, base colour from a texture on UVMap.001.
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.8, 1.9, 2.5), rotation=(math.pi / 2, 0, 0))
    screen = bpy.context.active_object
    screen.name = "screen"
    uv1 = screen.data.uv_layers.new(name="UVMap.001")
    for loop in uv1.data:
        loop.uv = (1.0 - loop.uv[0], loop.uv[1])
    mat = bpy.data.materials.new("screen")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    glow = nodes.new("ShaderNodeTexImage")
    glow.image = _image("glow", os.path.join(work, "glow.png"), [(1, 1, 1, 1), (0.2, 0.4, 1, 1)])
    links.new(glow.outputs["Color"], bsdf.inputs["Emission"])
    bsdf.inputs["Emission Strength"].default_value = 3.0
    base = nodes.new("ShaderNodeTexImage")
    base.image = _image("paint", os.path.join(work, "paint.png"), [(1, 0, 0, 1), (0, 1, 0, 1)])
    uvmap = nodes.new("ShaderNodeUVMap")
    uvmap.uv_map = "UVMap.001"
    links.new(uvmap.outputs["UV"], base.inputs["Vector"])
    links.new(base.outputs["Color"], bsdf.inputs["Base Color"])
    screen.data.materials.append(mat)
    # The add-on's export (no render), then osr-vk's loader on it (a preview at 1 spp).
    from osr_vk import export
    keep = os.path.join(work, "keep")
    os.makedirs(keep, exist_ok=True)
    gltf_path = export.export(bpy.context.evaluated_depsgraph_get(), keep).gltf_path
    with open(gltf_path) as f:
        gltf = json.load(f)
    log = subprocess.run([executable, "--mode", "preview", "--spp", "1", "--width", "16", "--height", "12",
                          "--quiet", "--offline", os.path.join(work, "preview.exr"), gltf_path],
                         check=True, capture_output=True, text=True).stderr
    materials = {m.get("name"): m for m in gltf.get("materials", [])}
    meshes = {n["name"]: gltf["meshes"][n["mesh"]] for n in gltf["nodes"] if "mesh" in n}
    attributes = {name: m["primitives"][0]["attributes"] for name, m in meshes.items()}
    problems = []
    if "COLOR_0" not in attributes["sphere"]:
        problems.append("the sphere's colour attribute (its Base Color) was not exported")
    if "COLOR_0" in attributes["floor"]:
        problems.append("the floor's colour attribute, which its material ignores, was exported")
    if materials["curtain"].get("alphaMode") != "BLEND":
        problems.append("the curtain is not alphaMode BLEND: %s" % materials["curtain"])
    screen_mat = materials["screen"]
    if "emissiveTexture" not in screen_mat or abs(
            screen_mat.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1) - 3) > 1e-6:
        problems.append("the screen's emission texture or strength is missing: %s" % screen_mat)
    base_info = screen_mat.get("pbrMetallicRoughness", {}).get("baseColorTexture", {})
    if base_info.get("texCoord") != 1 or "TEXCOORD_1" not in attributes["screen"]:
        problems.append("the screen's base colour does not read TEXCOORD_1: %s %s" % (base_info, attributes["screen"]))
    for word in ("COLOR_0", "TEXCOORD_1", "BLEND", "validation", "unsupported"):
        if word in log:
            problems.append("osr-vk warned about %s:\n%s" % (word, log))
    if problems:
        raise AssertionError("\n".join(problems))
    print("osr-vk test: materials exported with COLOR_0, alphaMode BLEND, emissive texture x 3, TEXCOORD_1")


def case_world(executable, work):
    # The world as --env, from the export alone (no render): a colour, an equirectangular
    # image as is, the same image at strength 2 from Blender's pixels (rows bottom-up there),
    # and a world shader it cannot carry (a warning, no environment).
    scene = blender_scene.build_scene(executable, WIDTH, HEIGHT)
    from osr_vk import export
    source = os.path.join(blender_scene.REPO, "scenes", "cornell", "cornell_cycles_4096spp.exr")

    def exported(name):
        directory = os.path.join(work, name)
        os.makedirs(directory)
        return export.export(bpy.context.evaluated_depsgraph_get(), directory)

    scene.world.color = (0.25, 0.5, 1.0)
    got = _layers(exported("colour").env_path)
    check = [float(np.abs(got[c] - v).max()) for c, v in zip("RGB", (0.25, 0.5, 1.0))]
    if max(check) > 1e-6:
        raise AssertionError("world colour written as %s" % check)
    world = scene.world
    world.use_nodes = True
    tree = world.node_tree
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(source)
    tree.links.new(texture.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    if exported("as_is").env_path != source:
        raise AssertionError("an .exr world at strength 1 should be handed over as is")
    tree.nodes["Background"].inputs["Strength"].default_value = 2.0
    got, want = _layers(exported("strength").env_path), _layers(source)
    err = max(float(np.abs(got[c] - 2 * want[c]).max()) for c in "RGB")
    if err > 1e-5:
        raise AssertionError("world image at strength 2 off by %g (flipped?)" % err)
    shader = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(shader.outputs[0], tree.nodes["World Output"].inputs["Surface"])
    # ... and a material node setup glTF cannot express: one more item of the same warning.
    material = bpy.data.materials["red"]
    diffuse = material.node_tree.nodes.new("ShaderNodeBsdfDiffuse")
    material.node_tree.links.new(diffuse.outputs[0],
                                 material.node_tree.nodes["Material Output"].inputs["Surface"])
    result = exported("shader")
    if result.env_path is not None or not any("world shader" in w for w in result.warnings):
        raise AssertionError("a non-Background world: %s %s" % (result.env_path, result.warnings))
    if not any("red (Diffuse BSDF)" in w for w in result.warnings):
        raise AssertionError("no warning for the Diffuse BSDF material: %s" % result.warnings)


def case_border(executable, work):
    # Resolution percentage, a render region cropped to the border and a second view layer:
    # each layer's result is the border's part of osr-vk's full frame at the scaled size.
    scene = blender_scene.build_scene(executable, WIDTH, HEIGHT)
    scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.seed = "path", 4, SEED
    scene.osr_vk.keep_directory = keep = os.path.join(work, "keep")
    r = scene.render
    r.resolution_percentage = 50  # 48 x 36
    r.use_border, r.use_crop_to_border = True, True
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = 0.25, 0.75, 0.5, 1.0
    scene.view_layers.new("second")
    bpy.ops.render.render()
    path = os.path.join(work, "border_layers.exr")
    save(path, "OPEN_EXR_MULTILAYER")
    got = _layers(path)
    full = _layers(os.path.join(keep, "render.exr"))
    w, h = WIDTH // 2, HEIGHT // 2
    x0, x1, y0, y1 = w // 4, 3 * w // 4, h // 2, h  # y0, y1 from the bottom, as Blender's
    for layer in ("ViewLayer", "second"):
        mine = got.get(layer + ".Combined.G")
        if mine is None:
            raise AssertionError("no result for view layer %s: %s" % (layer, sorted(got)))
        want = full["G"][h - y1:h - y0, x0:x1]
        if mine.shape != want.shape or float(np.abs(mine - want).max()) > 1e-5:
            raise AssertionError("layer %s: %s, expected the %s border region"
                                 % (layer, mine.shape, want.shape))


def case_f12(executable, work):
    # Blender's UI (under Xvfb): F12 renders in a job thread, where the add-on must hand the
    # glTF export to the main thread. Timers drive it; the script returns to the UI loop.
    def area(kind):
        window = bpy.context.window_manager.windows[0]
        areas = [a for a in window.screen.areas if a.type == kind]
        return window, max(areas, key=lambda a: a.width * a.height)

    def start():
        window, view3d = area("VIEW_3D")
        with bpy.context.temp_override(window=window, area=view3d):
            scene = blender_scene.build_scene(executable, WIDTH, HEIGHT, reset=False)
        scene.osr_vk.mode, scene.osr_vk.samples, scene.osr_vk.seed = "path", SAMPLES, SEED
        scene.osr_vk.keep_directory = os.path.join(work, "keep")
        # No context override around the render: under one, Blender reads context members
        # from C without the GIL while the render job's Python thread holds it (a crash).
        bpy.ops.render.render("INVOKE_DEFAULT")
        bpy.app.timers.register(finish, first_interval=1.0)

    def finish():
        if bpy.app.is_job_running("RENDER"):
            return 0.25
        mine = os.path.join(work, "blender.exr")
        save(mine, "OPEN_EXR")
        check_against_reference(executable, work, os.path.join(work, "keep"), mine)
        print("osr-vk test: case f12 done")
        bpy.ops.wm.quit_blender()
        return None

    bpy.app.timers.register(start, first_interval=0.5)
    return "later"


def case_animation_f12(executable, work):
    # Ctrl-F12 in Blender's UI (under Xvfb): Render Animation in a job thread, the animation
    # exported on the main thread while the job waits; one osr-vk run, frames as in animation.
    def start():
        window = bpy.context.window_manager.windows[0]
        view3d = max((a for a in window.screen.areas if a.type == "VIEW_3D"),
                     key=lambda a: a.width * a.height)
        with bpy.context.temp_override(window=window, area=view3d):
            scene = blender_scene.build_scene(executable, *SHOT_SIZE, reset=False)
        _animate(scene, work)
        state["pids"] = watch.__enter__().pids
        bpy.ops.render.render("INVOKE_DEFAULT", animation=True)  # no override: as in f12
        bpy.app.timers.register(finish, first_interval=1.0)

    def finish():
        if bpy.app.is_job_running("RENDER"):
            return 0.25
        watch.__exit__()
        scene = bpy.context.scene
        command = open(os.path.join(scene.osr_vk.keep_directory, "command.txt")).read()
        pids = sorted(state["pids"])
        print("osr-vk test: Ctrl-F12, osr-vk pids %s" % pids)
        if "--frames %d-%d" % (SHOT_FIRST, SHOT_LAST) not in command or len(pids) != 1:
            raise AssertionError("not one osr-vk --frames run: %s %s" % (pids, command))
        _check_shot_frames(executable, work, scene)
        print("osr-vk test: case animation_f12 done")
        bpy.ops.wm.quit_blender()
        return None

    watch, state = _Watch(), {}
    bpy.app.timers.register(start, first_interval=0.5)
    return "later"


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    case, executable, work = args[:3]
    os.makedirs(work, exist_ok=True)
    cases = {"render": case_render, "cancel": case_cancel, "missing": case_missing,
             "failed": case_failed, "install": case_install, "cycles": case_cycles,
             "world": case_world, "border": case_border, "f12": case_f12,
             "animation": case_animation, "animation_cancel": case_animation_cancel,
             "animation_fallback": case_animation_fallback,
             "animation_timing": case_animation_timing, "animation_f12": case_animation_f12,
             "materials": case_materials}
    if cases[case](executable, work, *args[3:]) != "later":
        print("osr-vk test: case %s done" % case)


main()
