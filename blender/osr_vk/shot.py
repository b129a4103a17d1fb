# Render Animation in one osr-vk run: Blender calls the engine once per frame, but osr-vk
# --frames renders a whole shot in one process (start-up, BVH and integrator paid once,
# docs/animation.md). A Shot starts that process for the frames still to come, and each engine
# call waits for its frame's EXR, which osr-vk writes under a temporary name and renames when
# whole. Knows nothing of Blender (tests/blender drive it directly).
import os
import shutil

from . import process

# osr-vk's frame numbers are at most six digits (src/app/frames.cpp).
MAX_OSR_FRAME = 999999


class Failed(Exception):
    """osr-vk ended before writing a frame: its exit code and last output lines."""

    def __init__(self, code, tail):
        super().__init__("exit %s" % code)
        self.code, self.tail = code, tail


class Plan:
    """Which Blender frames a shot renders and osr-vk's frame number of each. Blender's glTF
    exporter writes frame f at f / fps seconds (fps: the scene's Frame Rate, without its
    base), and osr-vk's frame k is at k / fps' seconds: with fps' = fps / step, k = f / step."""

    def __init__(self, first, last, step, fps):
        self.frames = list(range(first, last + 1, step))
        self.step, self.fps = step, fps

    def osr_frame(self, frame):
        return frame // self.step

    def args(self):
        return ["--frames", "%d-%d" % (self.osr_frame(self.frames[0]), self.osr_frame(self.frames[-1])),
                "--fps", repr(self.fps / self.step)]


def plan(first, last, step, fps):
    """A Plan for Blender frames first, first + step, ... up to last, or the reason (a string)
    why osr-vk --frames cannot render them at the glTF's times."""
    if step > 1 and first % step != 0:
        return ("frame step %d from frame %d (osr-vk's frame k is at k x %d / %g s: the step "
                "must divide the first frame)" % (step, first, step, fps))
    if first < 0 or last // step > MAX_OSR_FRAME:
        return "frames beyond osr-vk's 0 to %d" % MAX_OSR_FRAME
    if fps <= 0:
        return "frame rate %g" % fps
    return Plan(first, last, step, fps)


def frame_pattern(directory, extension):
    """osr-vk's name for a shot's files ('#' replaced by the frame number) and Python's."""
    return (os.path.join(directory, "frame_######" + extension),
            os.path.join(directory, "frame_%06d" + extension))


class Shot:
    """One `osr-vk --frames` run. `command` must write the EXR of osr-vk frame k to
    exr_format % k (frame_pattern); on_line, given to each call, gets every output line, and
    the log file at log_path (if any) too. gltf_path: the scene file osr-vk reads."""

    def __init__(self, command, shot_plan, exr_format, work, remove_work, log_path=None,
                 gltf_path=""):
        self.plan, self.exr_format, self.gltf_path = shot_plan, exr_format, gltf_path
        self.work, self.remove_work = work, remove_work  # a temporary folder is removed at stop
        self.warnings, self.reported = [], 0  # osr-vk's warnings, how many Blender was told
        self.served = None  # the last Blender frame handed out
        self.announced = None  # osr-vk's last "frame F/N" line: (F, N)
        self._log = open(log_path, "w", encoding="utf-8") if log_path else None
        try:
            self.child = process.Child(command)
        except OSError:
            if self._log:
                self._log.close()
            raise

    def _reader(self, on_line):
        def read(line):
            if self._log is not None:
                self._log.write(line + "\n")
            self.announced = process.parse_frame(line) or self.announced
            on_line(line)
        return read

    def serves(self, frame):
        """Whether `frame` is one of this shot's frames still to come."""
        return frame in self.plan.frames and (self.served is None or frame > self.served)

    def last(self, frame):
        return frame == self.plan.frames[-1]

    def wait(self, frame, on_line, should_stop, poll_s=0.1):
        """The EXR of Blender frame `frame` once osr-vk has written it. Cancelled (osr-vk
        stopped and reaped) when should_stop() turns true first; Failed when osr-vk ends
        without writing it."""
        path, on_line = self.exr_format % self.plan.osr_frame(frame), self._reader(on_line)
        while not os.path.isfile(path):
            if should_stop():
                self.stop()
                raise process.Cancelled()
            if not self.child.pump(poll_s, on_line):
                code = self.child.wait(should_stop, poll_s)
                if os.path.isfile(path):  # renamed while the output closed
                    break
                self.stop()
                raise Failed(code, self.child.tail)
        self.served = frame
        if self._log:
            self._log.flush()
        return path

    def finish(self, on_line, should_stop, poll_s=0.1):
        """After the last frame: reads the rest of the output, waits for the exit, cleans up.
        Returns the exit code."""
        on_line = self._reader(on_line)
        try:
            while self.child.pump(poll_s, on_line):
                if should_stop():
                    raise process.Cancelled()
            return self.child.wait(should_stop, poll_s)
        finally:
            self.stop()

    def stop(self):
        """Ends osr-vk if it still runs (terminated and reaped) and removes a temporary work
        folder; safe to call twice."""
        self.child.stop()
        if self._log:
            self._log.close()
            self._log = None
        if self.remove_work:
            shutil.rmtree(self.work, ignore_errors=True)
            self.remove_work = False
