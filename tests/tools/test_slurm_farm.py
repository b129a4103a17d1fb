#!/usr/bin/python3
"""tools/slurm/*.sbatch on a one-node Slurm started here (docs/farm.md): munged, slurmctld and
slurmd on localhost with a generated slurm.conf in a temporary folder. A 2-frame shot through
osr_farm.sbatch (a Dask scheduler and 2 workers started with srun, a scheduler file) and the
same shot through the job-array variant, both submitted at once; every frame complete and equal
to osr-vk's own render of that camera.

Skipped (with the reason) only where Debian's slurm-wlm and munge are not installed
(tools/install_deps.sh installs them); anything else that goes wrong fails.
Run by CTest (tools/slurm_farm) with OSR_BINARY_DIR naming the build.
"""
from __future__ import annotations

import getpass
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import exr_file  # noqa: E402
from make_interiors import make_scene  # noqa: E402

OSR_VK = Path(os.environ.get("OSR_BINARY_DIR", ROOT / "build")) / "osr-vk"
PROGRAMS = {"munged": "/usr/sbin/munged", "slurmctld": "/usr/sbin/slurmctld", "slurmd": "/usr/sbin/slurmd",
            "sbatch": shutil.which("sbatch") or "/usr/bin/sbatch", "squeue": shutil.which("squeue") or "/usr/bin/squeue"}
MISSING = [n for n, p in PROGRAMS.items() if not os.access(p, os.X_OK)]
SHOT = ["--mode", "path", "--spp", "1", "--seed", "2", "--width", "64", "--height", "64"]


@unittest.skipIf(MISSING, f"Slurm/munge not installed ({', '.join(MISSING)} missing): tools/install_deps.sh installs them")
class OneNodeSlurm(unittest.TestCase):
    def setUp(self):
        self.assertTrue(OSR_VK.is_file(), f"{OSR_VK}: not built (OSR_BINARY_DIR)")
        self.tmp = Path(tempfile.mkdtemp(prefix="osr_slurm_"))
        self.pids = []
        t = self.tmp
        for d in ("munge", "state", "spool", "log", "job"):
            (t / d).mkdir()
        (t / "munge" / "key").write_bytes(os.urandom(1024))
        (t / "munge" / "key").chmod(0o400)
        sock = t / "munge" / "sock"
        subprocess.run([PROGRAMS["munged"], "--force", f"--socket={sock}", f"--key-file={t / 'munge/key'}",
                        f"--log-file={t / 'munge/log'}", f"--pid-file={t / 'munge/pid'}",
                        f"--seed-file={t / 'munge/seed'}"], check=True)
        self.pids.append(t / "munge" / "pid")
        host, user = socket.gethostname().split(".")[0], getpass.getuser()
        port = 20000 + os.getpid() % 20000
        # CPUs above the machine's (config_overrides): the Dask job (3 tasks) and the array's two
        # tasks run at once; each task's osr-vk shares the real cores.
        (t / "slurm.conf").write_text(f"""ClusterName=osrtest
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={port}
SlurmdPort={port + 1}
SlurmUser={user}
SlurmdUser={user}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={sock}
StateSaveLocation={t / 'state'}
SlurmdSpoolDir={t / 'spool'}
SlurmctldPidFile={t / 'slurmctld.pid'}
SlurmdPidFile={t / 'slurmd.pid'}
SlurmctldLogFile={t / 'log/slurmctld.log'}
SlurmdLogFile={t / 'log/slurmd.log'}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
NodeName={host} NodeAddr=127.0.0.1 CPUs=8 State=UNKNOWN
PartitionName=farm Nodes=ALL Default=YES MaxTime=INFINITE State=UP
""")
        self.env = dict(os.environ, SLURM_CONF=str(t / "slurm.conf"), OSR_FARM_ROOT=str(ROOT))
        subprocess.run([PROGRAMS["slurmctld"], "-i", "-f", t / "slurm.conf"], check=True, env=self.env)
        self.pids.append(t / "slurmctld.pid")
        subprocess.run([PROGRAMS["slurmd"], "-f", t / "slurm.conf"], check=True, env=self.env)
        self.pids.append(t / "slurmd.pid")
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            r = subprocess.run(["sinfo", "-h", "-o", "%T"], capture_output=True, text=True, env=self.env)
            if r.stdout.strip() == "idle":
                break
            time.sleep(0.3)
        else:
            self.fail(f"the Slurm node never became idle: {r.stdout} {r.stderr}; {self.logs()}")

    def logs(self) -> str:
        return "".join(f"\n--- {p.name}\n" + p.read_text()[-1500:] for p in (self.tmp / "log").glob("*.log"))

    def tearDown(self):
        for pid_file in reversed(self.pids):
            try:
                os.kill(int(pid_file.read_text().split()[0]), signal.SIGTERM)
            except (OSError, ValueError):
                pass
        time.sleep(0.5)

    def test_shot_on_slurm(self):
        job = self.tmp / "job"
        make_scene(3, job / "scene", 2)
        scene = job / "scene" / "scene.gltf"

        def submit(*args):
            r = subprocess.run([PROGRAMS["sbatch"], "--parsable", *map(str, args)], capture_output=True, text=True,
                               env=self.env, cwd=job, check=True)
            return r.stdout.strip().split(";")[0]
        dask_job = submit("--ntasks=3", "-o", job / "dask.out", ROOT / "tools/slurm/osr_farm.sbatch",
                          "frames", "0-1", "--osr-vk", OSR_VK, "--", *SHOT, "--offline", job / "dask.exr", scene)
        array_job = submit("--array=0-1", "-o", job / "array_%a.out", ROOT / "tools/slurm/osr_frames_array.sbatch",
                           "--osr-vk", OSR_VK, "--", *SHOT, "--offline", job / "array.exr", scene)
        deadline = time.monotonic() + 400
        while time.monotonic() < deadline:
            r = subprocess.run([PROGRAMS["squeue"], "-h", "-j", f"{dask_job},{array_job}"], capture_output=True,
                               text=True, env=self.env)
            if r.returncode == 0 and not r.stdout.strip():
                break
            time.sleep(0.5)
        outs = "".join(f"\n--- {p.name}\n{p.read_text()[-3000:]}" for p in job.glob("*.out"))
        for n in range(2):
            one = job / f"one{n}.exr"
            subprocess.run([OSR_VK, *SHOT, "--camera", str(n), "--quiet", "--offline", one, scene], check=True)
            want = exr_file.read_raw(one)[1]
            for kind in ("dask", "array"):
                frame = job / f"{kind}.{n:04d}.exr"
                self.assertTrue(frame.is_file(), f"{frame} missing{outs}{self.logs()}")
                got = exr_file.read_raw(frame)[1]
                self.assertTrue(all((got[c] == v).all() for c, v in want.items()), f"{frame} differs")
        self.assertIn('"rendered": 2', (job / "dask.out").read_text(), outs)


if __name__ == "__main__":
    unittest.main(verbosity=2)
