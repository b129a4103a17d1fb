# The "osr-vk" render engine: F12 exports the scene (export.py), runs `osr-vk --offline` in a
# child process (process.py) with its progress in Blender's bar, and loads the EXR's layers
# into the render result: Combined plus Direct, Indirect, Albedo, Normal and Depth passes.
# Render Animation exports the scene once with its animation and serves every frame from one
# `osr-vk --frames` run (shot.py), unless the glTF cannot carry what moves: then frame by frame.
import os
import shlex
import shutil
import tempfile
import threading
import traceback

import bpy
import numpy as np

from . import exr, export, process, shot as shots

ADDON_DIR = os.path.dirname(os.path.abspath(__file__))

# (Blender pass, channels, channel ids, pass type, osr-vk EXR channels). osr-vk's normals are
# in glTF's +Y-up world; Blender's Normal pass is +Z-up: (x, y, z) -> (x, -z, y). Depth is the
# view-axis distance in both; osr-vk's 0 where nothing was hit is Blender's 1e10 (Cycles').
PASSES = (
    ("Direct", 3, "RGB", "COLOR", ("direct.R", "direct.G", "direct.B")),
    ("Indirect", 3, "RGB", "COLOR", ("indirect.R", "indirect.G", "indirect.B")),
    ("Albedo", 3, "RGB", "COLOR", ("albedo.R", "albedo.G", "albedo.B")),
    ("Normal", 3, "XYZ", "VECTOR", ("normal.X", "-normal.Z", "normal.Y")),
    ("Depth", 1, "Z", "VALUE", ("depth.Z",)),
)
BACKGROUND_DEPTH = 1e10


def addon_preferences(context=None):
    context = context or bpy.context
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon else None


def film_size(render):
    """The image osr-vk renders (resolution x percentage) and the border rectangle of it that
    Blender's render result holds, (x0, y0, x1, y1) with y from the bottom as in Blender."""
    scale = render.resolution_percentage / 100.0
    w, h = max(1, int(render.resolution_x * scale)), max(1, int(render.resolution_y * scale))
    if not render.use_border:
        return w, h, (0, 0, w, h)
    x0, x1 = int(render.border_min_x * w), int(render.border_max_x * w)
    y0, y1 = int(render.border_min_y * h), int(render.border_max_y * h)
    if x1 <= x0 or y1 <= y0:
        return w, h, (0, 0, w, h)
    return w, h, (x0, y0, x1, y1)


def build_command(executable, settings, exr_path, png_path, width, height, scene_export, extra=()):
    cmd = [executable, "--offline", exr_path, "--exr-float", "--mode", settings.mode,
           "--width", str(width), "--height", str(height), "--seed", str(settings.seed)]
    if png_path:
        cmd += ["--png", png_path]
    if settings.mode == "osr":
        if settings.passes > 0:
            cmd += ["--passes", str(settings.passes)]
        if settings.weights:
            cmd += ["--weights", bpy.path.abspath(settings.weights)]
    elif settings.samples > 0:
        cmd += ["--spp", str(settings.samples)]
    if settings.time_limit > 0:
        cmd += ["--time", "%g" % settings.time_limit]
    denoiser = getattr(settings, "denoiser", "mode")
    if denoiser == "network":
        cmd += ["--network", "default"]
    elif denoiser in ("atrous", "none"):
        cmd += ["--network", "none", "--filter", denoiser]
    if settings.device.strip():
        cmd += ["--device", settings.device.strip()]
    if scene_export.env_path:
        cmd += ["--env", scene_export.env_path]
    return cmd + list(extra) + [scene_export.gltf_path]


class _Animations:
    """Render Animation's state between Blender's per-frame engine calls, which do not share
    an engine instance: the running shot of each (scene, view layer) and the ones rendered
    frame by frame. A render job's start and end (handlers in __init__.py) reset it."""

    def __init__(self):
        self.lock = threading.Lock()
        self.shots, self.frame_by_frame = {}, set()

    def reset(self, *_):
        with self.lock:
            running, self.shots, self.frame_by_frame = list(self.shots.values()), {}, set()
        for s in running:
            s.stop()

    def drop(self, key):
        with self.lock:
            s = self.shots.pop(key, None)
        if s is not None:
            s.stop()


ANIMATIONS = _Animations()


def _progress_text(progress):
    done = ("%d %s" % (progress.done, progress.unit) if progress.unbounded()
            else "%d/%d %s" % (progress.done, progress.total, progress.unit))
    if progress.remaining_s is not None:
        done += " (~%.0f s left)" % progress.remaining_s
    return done


def _problem_line(tail, gltf_path):
    """osr-vk's error line from its last output lines, naming no temporary file."""
    errors = [l for l in tail if "warning" not in l and process.parse_progress(l) is None
              and process.parse_frame(l) is None]
    # The glTF is the add-on's temporary export, a path the user never chose.
    return errors[-1].replace(gltf_path, "the exported scene") if errors else None


def _shot_directory(keep, scene, view_layer):
    """The folder of a shot's files: a new temporary one, or the Keep folder cleared of a former
    shot's frames (they must not be taken for this one's). A scene that renders several view
    layers runs a shot for each at once, each in keep/<view layer>."""
    if not keep:
        return tempfile.mkdtemp(prefix="osr-vk-")
    if not scene.render.use_single_layer and sum(1 for layer in scene.view_layers if layer.use) > 1:
        keep = os.path.join(keep, bpy.path.clean_name(view_layer))
    os.makedirs(keep, exist_ok=True)
    for name in os.listdir(keep):
        if name.startswith("frame_") and name.endswith((".exr", ".png")):
            os.remove(os.path.join(keep, name))
    return keep


def on_main_thread(task, should_stop):
    """task() run on Blender's main thread, its result returned here. F12 renders in a job
    thread whose context is empty, and the glTF exporter needs the UI's (window, active
    object, view layer depsgraph) and must not race the UI for it: a timer hands it to the
    main thread, which keeps running while the job waits. A render that already runs on the
    main thread (background, or render.render() without INVOKE) calls it directly."""
    if threading.current_thread() is threading.main_thread():
        return task()
    state = {"started": False, "cancelled": False}
    lock, done = threading.Lock(), threading.Event()

    def timer():
        with lock:
            if state["cancelled"]:
                return None
            state["started"] = True
        try:
            state["value"] = task()
        except BaseException as e:  # handed to the render thread
            state["error"] = e
        finally:
            done.set()
        return None

    bpy.app.timers.register(timer, first_interval=0.0)
    while not done.wait(0.1):
        if should_stop():
            with lock:
                if not state["started"]:
                    state["cancelled"] = True
                    raise process.Cancelled()
            # Already exporting: let it finish (it writes into the work directory).
    if "error" in state:
        raise state["error"]
    return state["value"]


class OsrVkRenderEngine(bpy.types.RenderEngine):
    bl_idname = "OSR_VK"
    bl_label = "osr-vk"
    bl_use_preview = False
    bl_use_postprocess = True
    bl_use_eevee_viewport = True  # material preview in the viewport stays EEVEE's

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name, channels, ids, kind, _ in PASSES:
            self.register_pass(scene, renderlayer, name, channels, ids, kind)

    def render(self, depsgraph):
        scene = depsgraph.scene
        settings = scene.osr_vk
        prefs = addon_preferences()
        configured = prefs.executable if prefs else ""
        executable = process.find_executable(bpy.path.abspath(configured) if configured else "", ADDON_DIR)
        if executable is None:
            where = ("'%s' is not an executable file" % configured if configured else
                     "not on PATH nor next to the add-on (%s)" % ADDON_DIR)
            self.report({"ERROR"}, "osr-vk executable not found: %s; set it in the osr-vk "
                                   "render panel or the add-on preferences" % where)
            return
        keep = bpy.path.abspath(settings.keep_directory) if settings.keep_directory else ""
        if self.is_animation and settings.one_run_per_animation:
            try:
                if self._render_shot_frame(depsgraph, settings, executable, keep):
                    return
            except Exception as e:  # a bug here: a report, the traceback to the console only
                ANIMATIONS.drop((scene.name, depsgraph.view_layer.name))
                traceback.print_exc()
                self.report({"ERROR"}, "osr-vk add-on: internal error: %s: %s" % (type(e).__name__, e))
                return
        try:
            if keep:
                os.makedirs(keep, exist_ok=True)
            work = keep or tempfile.mkdtemp(prefix="osr-vk-")
        except OSError as e:
            self.report({"ERROR"}, "osr-vk: cannot create the work directory: %s" % e)
            return
        try:
            self._render_in(depsgraph, settings, executable, work)
        except Exception as e:  # a bug here: a report, the traceback to the console only
            traceback.print_exc()
            self.report({"ERROR"}, "osr-vk add-on: internal error: %s: %s" % (type(e).__name__, e))
        finally:
            if not keep:
                shutil.rmtree(work, ignore_errors=True)

    def _render_shot_frame(self, depsgraph, settings, executable, keep):
        """Render Animation's frame from the shot of this scene and view layer, started on its
        first frame. Returns False when this scene renders frame by frame (said once per job)."""
        scene = depsgraph.scene
        key, frame = (scene.name, depsgraph.view_layer.name), scene.frame_current
        with ANIMATIONS.lock:
            if key in ANIMATIONS.frame_by_frame:
                return False
            current = ANIMATIONS.shots.get(key)
        if current is not None and not current.serves(frame):
            ANIMATIONS.drop(key)  # a shot of another render
            current = None
        if current is None:
            current = self._start_shot(depsgraph, settings, executable, keep, key)
            if current is None:
                return key not in ANIMATIONS.frame_by_frame
        def on_line(line):
            progress = process.parse_progress(line)
            if progress is not None:
                self.update_progress(progress.fraction())
                where = " (%d/%d of the shot)" % current.announced if current.announced else ""
                self.update_stats("", "osr-vk: frame %d%s: %s" % (frame, where, _progress_text(progress)))
            elif "warning:" in line:
                current.warnings.append(line.split("warning:", 1)[1].strip())

        self.update_stats("", "osr-vk: frame %d, waiting for osr-vk" % frame)
        try:
            path = current.wait(frame, on_line, self.test_break)
        except process.Cancelled:
            ANIMATIONS.drop(key)
            self.report({"INFO"}, "osr-vk: render cancelled")
            return True
        except shots.Failed as e:  # an error report ends Render Animation (Blender's rule)
            ANIMATIONS.drop(key)
            why = _problem_line(e.tail, current.gltf_path) or "exit code %s" % e.code
            self.report({"ERROR"}, "osr-vk failed (exit %s): %s" % (e.code, why))
            return True
        if len(current.warnings) > current.reported:
            self.report({"WARNING"}, "osr-vk: not rendered as in Blender: "
                        + "; ".join(current.warnings[current.reported:]))
            current.reported = len(current.warnings)
        loaded = self._load_result(path, depsgraph)
        if current.last(frame) or not loaded:
            try:
                code = current.finish(on_line, self.test_break)
            except process.Cancelled:
                code = 0
            if code and loaded:
                self.report({"WARNING"}, "osr-vk exited with %s after the last frame" % code)
            ANIMATIONS.drop(key)
        return True

    def _start_shot(self, depsgraph, settings, executable, keep, key):
        """Exports the scene with its animation and starts osr-vk --frames for the frames of
        this Render Animation from the current one on. None when it did not start: an error
        was reported, or (ANIMATIONS.frame_by_frame) the animation cannot come through glTF."""
        scene = depsgraph.scene
        plan = shots.plan(scene.frame_current, scene.frame_end, max(1, scene.frame_step),
                          scene.render.fps)
        self.update_stats("", "osr-vk: exporting the animation")
        try:
            work = _shot_directory(keep, scene, depsgraph.view_layer.name)
        except OSError as e:
            self.report({"ERROR"}, "osr-vk: cannot create the work directory: %s" % e)
            return None
        started = None
        try:
            started = self._export_and_start(depsgraph, settings, executable, work, not keep, plan, key)
        finally:
            if started is None and not keep:
                shutil.rmtree(work, ignore_errors=True)
        if started is not None:
            with ANIMATIONS.lock:
                ANIMATIONS.shots[key] = started
        return started

    def _export_and_start(self, depsgraph, settings, executable, work, temporary, plan, key):
        frames = [depsgraph.scene.frame_current] if isinstance(plan, str) else plan.frames

        def task():
            reasons = [plan] if isinstance(plan, str) else export.animation_problems(depsgraph, frames)
            return reasons, None if reasons else export.export(depsgraph, work, animation=True)

        try:
            reasons, scene_export = on_main_thread(task, self.test_break)
        except process.Cancelled:
            self.report({"INFO"}, "osr-vk: render cancelled")
            return None
        except (export.ExportError, OSError) as e:
            self.report({"ERROR"}, "osr-vk: %s" % e)
            return None
        if reasons:
            with ANIMATIONS.lock:
                ANIMATIONS.frame_by_frame.add(key)
            self.report({"WARNING"}, "osr-vk: Render Animation frame by frame, one export and "
                        "osr-vk run each (the glTF cannot carry it): " + "; ".join(reasons))
            return None
        exr_pattern, exr_format = shots.frame_pattern(work, ".exr")
        width, height, _ = film_size(depsgraph.scene.render)
        cmd = build_command(executable, settings, exr_pattern, shots.frame_pattern(work, ".png")[0],
                            width, height, scene_export,
                            plan.args() + ["--temporal-reuse", "%g" % settings.temporal_reuse])
        try:
            with open(os.path.join(work, "command.txt"), "w", encoding="utf-8") as f:
                f.write(shlex.join(cmd) + "\n")
            started = shots.Shot(cmd, plan, exr_format, work, temporary,
                                 os.path.join(work, "osr-vk.log"), scene_export.gltf_path)
        except OSError as e:
            self.report({"ERROR"}, "osr-vk: cannot run %s: %s" % (executable, e.strerror or e))
            return None
        if scene_export.warnings:
            self.report({"WARNING"}, "osr-vk: not rendered as in Blender: " + "; ".join(scene_export.warnings))
        self.report({"INFO"}, "osr-vk: frames %d-%d in one run, osr-vk pid %d"
                    % (plan.frames[0], plan.frames[-1], started.child.pid))
        return started

    def _render_in(self, depsgraph, settings, executable, work):
        width, height, _ = film_size(depsgraph.scene.render)
        self.update_stats("", "osr-vk: exporting the scene")
        try:
            scene_export = on_main_thread(lambda: export.export(depsgraph, work), self.test_break)
        except process.Cancelled:
            self.report({"INFO"}, "osr-vk: render cancelled")
            return
        except (export.ExportError, OSError) as e:
            self.report({"ERROR"}, "osr-vk: %s" % e)
            return
        exr_path = os.path.join(work, "render.exr")
        cmd = build_command(executable, settings, exr_path, os.path.join(work, "render.png"),
                            width, height, scene_export)
        with open(os.path.join(work, "command.txt"), "w", encoding="utf-8") as f:
            f.write(shlex.join(cmd) + "\n")
        osr_warnings, log = [], open(os.path.join(work, "osr-vk.log"), "w", encoding="utf-8")

        def on_line(line):
            log.write(line + "\n")
            progress = process.parse_progress(line)
            if progress is not None:
                self.update_progress(progress.fraction())
                self.update_stats("", "osr-vk: " + _progress_text(progress))
            elif "warning:" in line:
                osr_warnings.append(line.split("warning:", 1)[1].strip())

        self.update_stats("", "osr-vk: starting %s" % os.path.basename(executable))
        try:
            code, tail = process.run(cmd, on_line, self.test_break)
        except process.Cancelled:
            self.report({"INFO"}, "osr-vk: render cancelled")
            return
        except OSError as e:
            self.report({"ERROR"}, "osr-vk: cannot run %s: %s" % (executable, e.strerror or e))
            return
        finally:
            log.close()
        problems = scene_export.warnings + osr_warnings
        if problems:
            self.report({"WARNING"}, "osr-vk: not rendered as in Blender: " + "; ".join(problems))
        if code != 0:
            why = _problem_line(tail, scene_export.gltf_path) or "exit code %d" % code
            self.report({"ERROR"}, "osr-vk failed (exit %d): %s" % (code, why))
            return
        self._load_result(exr_path, depsgraph)

    def _load_result(self, exr_path, depsgraph):
        """osr-vk's EXR into the render result; False (an error reported) when it cannot be."""
        width, height, border = film_size(depsgraph.scene.render)
        try:
            w, h, planes = exr.read_layers(exr_path)
        except exr.ExrError as e:
            self.report({"ERROR"}, "osr-vk: %s" % e)
            return False
        if (w, h) != (width, height):
            self.report({"ERROR"}, "osr-vk wrote a %dx%d image, %dx%d asked" % (w, h, width, height))
            return False
        self._write_result(planes, border, depsgraph.view_layer.name)
        return True

    def _write_result(self, planes, border, view_layer):
        x0, y0, x1, y1 = border
        bw, bh = x1 - x0, y1 - y0

        def plane(name):  # osr-vk's rows run top-down, Blender's bottom-up; then the border
            sign = -1.0 if name.startswith("-") else 1.0
            name = name.lstrip("-")
            p = planes.get(name)
            if p is None:
                return np.zeros((bh, bw), np.float32)
            return sign * p[::-1][y0:y1, x0:x1]

        result = self.begin_result(0, 0, bw, bh, layer=view_layer)
        try:
            layer = result.layers[0]
            combined = np.dstack([plane("R"), plane("G"), plane("B"), np.ones((bh, bw), np.float32)])
            layer.passes["Combined"].rect.foreach_set(combined.reshape(-1, 4))
            for name, _, _, _, channels in PASSES:
                target = layer.passes.find(name)
                if target >= 0:
                    data = np.dstack([plane(c) for c in channels]).reshape(-1, len(channels))
                    if name == "Depth":
                        data = np.where(data > 0.0, data, BACKGROUND_DEPTH)
                    layer.passes[target].rect.foreach_set(np.ascontiguousarray(data, np.float32))
        finally:
            self.end_result(result)
