#!/usr/bin/env python3
"""CTest driver for the Blender add-on: runs one case of addon_cases.py in headless Blender
and checks what only the outside can see: the exit code, that no Python traceback reached the
output, and (cancel) that no osr-vk process outlives Blender.

usage: test_blender_addon.py CASE --blender BLENDER --osr-vk OSR_VK --zip osr_vk.zip --work DIR
"""
import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


# Output a case must produce: the add-on's reports (Blender prints an operator's reports when
# it ends) and its status lines (background Blender prints each, after "Fra:N ... |").
EXPECTED_OUTPUT = {
    "animation": ["Info: osr-vk: frames 2-5 in one run",
                  "| osr-vk: frame 3 (2/4 of the shot): 8/8 spp"],
    "animation_cancel": ["Info: osr-vk: frames 1-4 in one run", "Info: osr-vk: render cancelled"],
    "animation_fallback": ["Warning: osr-vk: Render Animation frame by frame", "animated material copper"],
}


def osr_vk_processes(executable):
    """Pids of running processes whose executable is `executable`."""
    target, pids = os.path.realpath(executable), []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if os.path.realpath("/proc/%s/exe" % entry) == target:
                    pids.append(int(entry))
            except OSError:
                pass
    return pids


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("case", choices=["render", "cancel", "missing", "failed", "install", "cycles", "world", "border", "f12",
                                           "animation", "animation_cancel", "animation_fallback",
                                           "animation_timing", "animation_f12", "materials"])
    parser.add_argument("--blender", required=True)
    parser.add_argument("--osr-vk", required=True)
    parser.add_argument("--zip", help="osr_vk.zip, for the install case")
    parser.add_argument("--work", required=True)
    args = parser.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    cmd = [args.blender, "-b", "--factory-startup", "--python-exit-code", "1",
           "--python", os.path.join(HERE, "addon_cases.py"), "--",
           args.case, os.path.abspath(args.osr_vk), os.path.abspath(args.work)]
    if args.case in {"f12", "animation_f12"}:  # Blender's UI, on a virtual display
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24"] + [c for c in cmd if c != "-b"]
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")  # no __pycache__ in the source tree
    if args.case == "install":  # a user directory of its own, not the user's
        cmd.append(os.path.abspath(args.zip))
        env["BLENDER_USER_SCRIPTS"] = os.path.join(args.work, "user_scripts")
        env["BLENDER_USER_CONFIG"] = os.path.join(args.work, "user_config")
    start = time.monotonic()
    # A session of its own, so that a hung run is ended with everything it started (xvfb-run,
    # Xvfb, Blender, osr-vk).
    run = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           env=env, start_new_session=True)
    try:
        out, _ = run.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        os.killpg(run.pid, signal.SIGKILL)
        out, _ = run.communicate()
        print(out)
        print("FAILED: blender did not finish in 240 s")
        return 1
    took = time.monotonic() - start
    failures = []
    if "osr-vk test: case %s done" % args.case not in out:
        failures.append("the case did not finish")
    # In the background Blender exits 1 after an operator reported an error: expected when the
    # case is an error report, a failure otherwise.
    allowed = {0, 1} if args.case in {"missing", "failed"} else {0}
    if run.returncode not in allowed:
        failures.append("blender exited with %d" % run.returncode)
    if "Traceback" in out:
        failures.append("a Python traceback in Blender's output")
    for line in EXPECTED_OUTPUT.get(args.case, ()):
        if line not in out:
            failures.append("no '%s' in the output" % line)
    # The osr-vk the cancel case interrupted must be gone now that Blender is (other tests may
    # run osr-vk meanwhile: only that pid is checked).
    for pid in re.findall(r"osr-vk pid (\d+)", out):
        if int(pid) in osr_vk_processes(args.osr_vk):
            failures.append("osr-vk (pid %s) still running after the cancel" % pid)
    for line in out.splitlines():
        if line.startswith("osr-vk test:") or line.startswith("Error:"):
            print(line)
    print("blender run: %.1f s" % took)
    if failures:
        print(out)
        print("FAILED: " + "; ".join(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
