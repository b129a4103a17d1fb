# Runs osr-vk as a child process: finds the executable, streams its progress lines, stops it
# on cancel and always reaps it. Knows nothing of Blender (tests/blender drive it directly).
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import time

# "osr-vk: 12/64 spp, 3.1 s elapsed, ~13.2 s remaining" (src/app/cmd_render.cpp). Matched
# loosely: any "N/M unit" pair, optional elapsed and remaining seconds, so that rewording the
# line keeps the bar moving.
_PROGRESS = re.compile(r"(\d+)\s*/\s*(\d+)\s*([A-Za-z]+)?")
_ELAPSED = re.compile(r"([\d.]+)\s*s\s+elapsed")
_REMAINING = re.compile(r"~?\s*([\d.]+)\s*s\s+remaining")
# --time alone leaves out "/M": "osr-vk: 12 passes, 3.1 s elapsed, ~13.2 s remaining" (taken
# only with "elapsed", so the summary line "osr-vk: 96x72, 16 spp in 0.63 s" is not progress).
_UNBOUNDED = re.compile(r"^osr-vk:\s*(\d+)\s+([A-Za-z]+)")
# A unit running in slices: "osr-vk: 0/32 passes (+40% of the next), ...".
_PARTIAL = re.compile(r"\(\+(\d+)%\s+of\s+the\s+next\)")
# An animation render (--frames) announces each frame before its progress lines:
# "osr-vk: frame 2/48 (frame 1 at 0.042 s)"; its N/M counts frames, not units.
_FRAME = re.compile(r"^osr-vk:\s*frame\s+(\d+)\s*/\s*(\d+)")


class Progress:
    def __init__(self, done, total, unit, elapsed_s, remaining_s, line, partial=0.0):
        self.done, self.total, self.unit = done, total, unit  # total 0: only --time bounds it
        self.elapsed_s, self.remaining_s, self.line = elapsed_s, remaining_s, line
        self.partial = partial  # of the unit in progress, 0 to 1

    def unbounded(self):
        """Only --time bounds the render: osr-vk announces no or a huge unit target."""
        return self.total <= 0 or self.total >= 1 << 20

    def fraction(self):
        # Time-limited renders: elapsed / (elapsed + remaining).
        units = self.done + self.partial
        if self.elapsed_s is not None and self.remaining_s is not None:
            by_time = self.elapsed_s / max(self.elapsed_s + self.remaining_s, 1e-9)
            if self.unbounded():
                return min(1.0, by_time)
            return min(1.0, max(units / self.total, by_time))
        return min(1.0, units / self.total) if self.total > 0 else 0.0


def parse_progress(line):
    """A Progress for an osr-vk progress line, None for any other line."""
    if not line.startswith("osr-vk:") or "warning" in line or "error" in line:
        return None
    if _FRAME.search(line):
        return None
    e, r, part = _ELAPSED.search(line), _REMAINING.search(line), _PARTIAL.search(line)
    m = _PROGRESS.search(line)
    if m:
        done, total, unit = int(m.group(1)), int(m.group(2)), m.group(3) or ""
    else:
        m = _UNBOUNDED.search(line)
        if not m or not e:
            return None
        done, total, unit = int(m.group(1)), 0, m.group(2)
    return Progress(done, total, unit, float(e.group(1)) if e else None,
                    float(r.group(1)) if r else None, line,
                    min(1.0, int(part.group(1)) / 100.0) if part else 0.0)


def parse_frame(line):
    """(frame index from 1, frames in the shot) for an --frames announcement, else None."""
    m = _FRAME.search(line)
    return (int(m.group(1)), int(m.group(2))) if m else None


def find_executable(configured, addon_dir):
    """The osr-vk to run: `configured` if set, else on PATH, else next to the add-on."""
    if configured:
        path = os.path.abspath(os.path.expanduser(configured))
        return path if os.path.isfile(path) and os.access(path, os.X_OK) else None
    name = "osr-vk.exe" if sys.platform == "win32" else "osr-vk"
    for candidate in (os.path.join(addon_dir, name), os.path.join(addon_dir, "bin", name)):
        if os.path.isfile(candidate):
            if not os.access(candidate, os.X_OK):
                # Blender's add-on installer unzips without Unix modes: the bundled osr-vk
                # arrives without its executable bit.
                try:
                    os.chmod(candidate, os.stat(candidate).st_mode | 0o755)
                except OSError:
                    continue
            return candidate
    return shutil.which(name)


def _parent_death_signal():
    # Linux: the child gets SIGTERM if Blender dies mid-render (no orphan renders). Resolved
    # here, not in the forked child, so the child only makes the call.
    if not sys.platform.startswith("linux"):
        return None
    try:
        import ctypes
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    return lambda: prctl(1, int(signal.SIGTERM))  # PR_SET_PDEATHSIG


_DIE_WITH_PARENT = _parent_death_signal()


class Cancelled(Exception):
    pass


class Child:
    """A running osr-vk whose output is read when asked (pump): run() reads one to its end, an
    animation keeps one across Blender's per-frame engine calls (shot.py). stop() terminates
    and reaps it; call it in every case (it also closes the output)."""

    def __init__(self, command):
        # osr-vk rewrites its progress line in place on a terminal (every ~0.25 s) but prints
        # one only every 5 s into a pipe: give it a pseudo-terminal where there is one.
        self._master = slave = None
        if sys.platform != "win32":
            try:
                import pty
                self._master, slave = pty.openpty()
            except OSError:
                self._master = slave = None
        kwargs = {"stdin": subprocess.DEVNULL}
        if slave is not None:
            kwargs.update(stdout=slave, stderr=slave)
        else:
            kwargs.update(stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        if _DIE_WITH_PARENT is not None:
            kwargs["preexec_fn"] = _DIE_WITH_PARENT
        try:
            self.proc = subprocess.Popen(command, **kwargs)
        except OSError:
            if self._master is not None:
                os.close(self._master)
                os.close(slave)
            raise
        if slave is not None:
            os.close(slave)
        self._fd = self._master if self._master is not None else self.proc.stdout.fileno()
        self.tail, self._pending, self._open = [], "", True

    @property
    def pid(self):
        return self.proc.pid

    def _emit(self, line, on_line):
        self.tail = (self.tail + [line])[-20:]
        on_line(line)

    def pump(self, timeout_s, on_line):
        """Waits up to timeout_s for output and calls on_line(text) for each whole line.
        Returns False once the output is closed (the process ended or is ending)."""
        if not self._open:
            return False
        ready, _, _ = select.select([self._fd], [], [], timeout_s)
        if not ready:
            if self.proc.poll() is not None and self._master is None:
                self._close(on_line)
            return self._open
        try:
            chunk = os.read(self._fd, 65536)
        except OSError:  # EIO: the pty's other side is closed
            chunk = b""
        if not chunk:
            self._close(on_line)
            return False
        self._pending += chunk.decode("utf-8", "replace")
        *lines, self._pending = re.split(r"[\r\n]+", self._pending)
        if self._pending[-1:].isspace():  # a tty progress line is padded, not ended
            lines.append(self._pending)
            self._pending = ""
        for line in lines:
            line = line.strip()
            if line:
                self._emit(line, on_line)
        return True

    def _close(self, on_line):
        self._open = False
        if self._pending.strip():
            self._emit(self._pending.strip(), on_line)
        self._pending = ""

    def wait(self, should_stop, poll_s=0.1):
        """The exit code once the process has ended; Cancelled (process stopped) when
        should_stop() turns true first."""
        while self.proc.poll() is None:
            if should_stop():
                self.stop()
                raise Cancelled()
            time.sleep(poll_s)
        return self.proc.returncode

    def stop(self):
        """Terminates the process if it still runs (killed after 5 s), reaps it and closes its
        output; safe to call twice."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if self._fd is not None:
            if self._master is not None:
                os.close(self._master)
            elif self.proc.stdout:
                self.proc.stdout.close()
            self._fd = None
        self._open = False


def run(command, on_line, should_stop, poll_s=0.1):
    """Runs `command`; calls on_line(text) for each stderr/stdout line. should_stop() is polled
    every poll_s; when it turns true the process is terminated, reaped and Cancelled raised.
    Returns (exit code, the output's last lines)."""
    child = Child(command)
    try:
        while child.pump(poll_s, on_line):
            if should_stop():
                raise Cancelled()
        return child.wait(should_stop, poll_s), child.tail
    finally:
        child.stop()
