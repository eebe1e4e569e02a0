"""Benchmark: the whole `armcli simulate --urdf` process vs the equivalent MuJoCo script.

1. Whole process: a 120 s pick-like trajectory (121 points, each side reading all of them)
   at dt = 0.5 ms (240,000 steps) on the standalone arm, PD gains Kp 50, Kd 5, each side a
   fresh process as a user runs it, in turn (A B A B ...) so the ratio is taken pair by
   pair. The same commands for one step give the set-up (imports, model, checks), which is
   cut to give the stepping alone.
2. Peak memory (the process's max RSS) of both, and of armcli on 1.8 M steps (900 s at
   0.5 ms) writing its states at 10 Hz: memory follows the output rate, not the steps; next
   to it the same run through the library keeping every step's state.
3. Start-up: `armcli simulate --help` next to `python -c pass`, and what importing the
   simulate command costs, by module (`python -X importtime`).

Every process runs with Python's bytecode cache on (in a temporary PYTHONPYCACHEPREFIX,
warmed by an untimed first run), as an installed package has it: an environment with
PYTHONDONTWRITEBYTECODE=1 would otherwise recompile armcli's modules at every start
(~0.1 CPU s) while numpy, Pinocchio and MuJoCo load their installed caches.

Run with `make bench` (or `python bench/bench_process.py [--quick]`). Not a test: numbers
depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
DT = 5e-4  # [s]
KP, KD = 50.0, 5.0
WHOLE_S, MEMORY_S = 120.0, 900.0  # [s] trajectories of the two comparisons
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
CYCLE = [(0.6, 0.4, 1.0), (0.9, 1.2, 2.0), (0.9, 1.2, 2.5), (0.5, 0.8, 3.5), (0.3, 0.3, 5.0)]
MUJOCO_SCRIPT = """
import sys
import mujoco
import numpy as np
urdf, duration, dt, kp, kd = sys.argv[1], float(sys.argv[2]), {dt}, {kp}, {kd}
knots = np.array({knots})
xml = open(urdf).read().replace(
    "</robot>", '<mujoco><compiler discardvisual="true" fusestatic="false"/></mujoco></robot>')
m = mujoco.MjModel.from_xml_string(xml)
m.opt.timestep = dt
m.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
m.dof_damping[:] = m.dof_damping + kd
d = mujoco.MjData(m)
d.qpos[:] = knots[0, :2]
steps = round(duration / dt)
t = np.arange(steps + 1) * dt
q_ref = np.column_stack([np.interp(t, knots[:, 2], knots[:, j]) for j in (0, 1)])
v_ref = np.gradient(q_ref, dt, axis=0)
out = np.empty_like(q_ref)
for k in range(steps):
    d.qfrc_applied[:] = kp * (q_ref[k] - d.qpos) + kd * v_ref[k]
    mujoco.mj_step(m, d)
    out[k + 1] = d.qpos
"""

KEEP_EVERY_STEP = """
import sys
from pathlib import Path
from armcli.sim import job as simjob
from armcli.sim.options import SimOptions
from armcli.sim.simulate import simulate
from armcli.urdf.source import read_robot
traj, urdf = Path(sys.argv[1]), Path(sys.argv[2])
duration, dt = float(sys.argv[3]), float(sys.argv[4])
opts = SimOptions(trajectory=traj, kp=(50.0,), kd=(5.0,), dt=dt, duration=duration)
job = simjob.prepare(read_robot(urdf), opts)
simulate(job.robot, job.reference, job.q0, job.duration, job.config)
"""


def trajectory(duration: float) -> tuple[str, list[tuple[float, float, float]]]:
    """YAML text and knots (q1, q2, t) of `duration` s of pick cycles from (0.2, 0.2)."""
    knots = [(0.2, 0.2, 0.0)]
    lines = ["joint_names: [arm_base_forearm_joint, forearm_hand_joint]", "points:"]
    for c in range(round(duration / 5.0)):
        for q1, q2, t in CYCLE:
            knots.append((q1, q2, 5.0 * c + t))
            lines.append(f" - {{positions: [{q1}, {q2}], time_from_start: {5.0 * c + t}}}")
    return "\n".join(lines) + "\n", knots


def run_once(cmd: list[str]) -> tuple[float, float, float]:
    """Wall seconds, CPU seconds (user + system) and peak RSS [MiB] of one process, from the
    kernel's accounting. CPU time is what a busy machine disturbs least."""
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"failed ({proc.returncode}): {' '.join(cmd)}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def paired(a: list[str], b: list[str], repeats: int) -> tuple[list[float], list[float], float]:
    """A and B in turn; their CPU seconds, and the median of the pairwise ratios."""
    run_once(a), run_once(b)  # untimed: fills the bytecode cache
    ta, tb = [], []
    for _ in range(repeats):
        ta.append(run_once(a)[1])
        tb.append(run_once(b)[1])
    ratio = statistics.median(x / y for x, y in zip(ta, tb, strict=True))
    return ta, tb, ratio


def whole_process(
    repeats: int, armcli: Callable[[float], list[str]], mujoco: Callable[[float], list[str]]
) -> None:
    duration = WHOLE_S
    steps = round(duration / DT)
    ta, tb, ratio = paired(armcli(duration), mujoco(duration), repeats)
    sa, sb, _ = paired(armcli(DT), mujoco(DT), repeats)
    med = statistics.median
    cut = (med(ta) - med(sa)) / (med(tb) - med(sb))
    print(f"\nwhole process, {duration:g} s trajectory at dt = {DT} s ({steps} steps), "
          f"CPU seconds, median of {repeats} pairs")  # fmt: skip
    head = ("process", "total [s]", "set-up [s]", "µs/step", "peak [MiB]")
    print("  ".join(f"{c:>11}" if i else f"{c:<34}" for i, c in enumerate(head)))
    for name, tot, setup, cmd in (
        ("MuJoCo script (PD in Python)", tb, sb, mujoco(duration)),
        ("armcli simulate --urdf", ta, sa, armcli(duration)),
    ):
        peak = run_once(cmd)[2]
        cells = (name, f"{med(tot):.2f}", f"{med(setup):.2f}",
                 f"{(med(tot) - med(setup)) / steps * 1e6:.2f}", f"{peak:.0f}")  # fmt: skip
        print("  ".join(f"{c:>11}" if i else f"{c:<34}" for i, c in enumerate(cells)))
    print(f"armcli / MuJoCo, whole process: {ratio:.3f}x (pairwise median; target <= 0.3x)")
    print(f"armcli / MuJoCo, stepping alone (set-up cut): {cut:.3f}x")


def memory(armcli: Callable[..., list[str]], out: Path, traj: Path, urdf: Path) -> None:
    """Peak RSS of a 1.8 M-step run writing its states at 10 Hz, and of the same run
    through the library keeping every step's state (what `simulate` did before)."""
    steps = round(MEMORY_S / DT)
    _, cpu, peak = run_once(armcli(MEMORY_S, "--output", str(out), "--rate", "10", traj=MEMORY_S))
    _, short_cpu, short_peak = run_once(armcli(DT))
    every = [sys.executable, "-c", KEEP_EVERY_STEP, str(traj), str(urdf), str(MEMORY_S), str(DT)]
    _, _, every_peak = run_once(every)
    print(f"\n{steps:,} steps (--duration {steps * DT:g} at dt = {DT}), states at 10 Hz:")
    print(f"  peak {peak:.0f} MiB ({short_peak:.0f} MiB for one step); {cpu:.2f} CPU s "
          f"({(cpu - short_cpu) / steps * 1e6:.2f} µs/step)")  # fmt: skip
    print(f"  the same run keeping every step's state (library, record=None): {every_peak:.0f} MiB")


def startup(repeats: int) -> None:
    """`simulate --help` vs `python -c pass`, and the import cost by module."""
    help_cmd = [str(BIN / "armcli"), "simulate", "--help"]
    bare = [sys.executable, "-c", "pass"]
    th, tp, _ = paired(help_cmd, bare, repeats)
    print(f"\nstart-up: `armcli simulate --help` {statistics.median(th):.3f} CPU s, "
          f"`python -c pass` {statistics.median(tp):.3f} CPU s")  # fmt: skip
    for module in ("armcli.commands.simulate", "armcli.check.gate", "pinocchio"):
        r = subprocess.run([sys.executable, "-X", "importtime", "-c", f"import {module}"],
                           capture_output=True, text=True, check=True, env=ENV)  # fmt: skip
        # "import time: self | cumulative | name", nested names indented by two spaces
        rows = re.findall(r"\|\s*(\d+) \| ( *)(\S+)$", r.stderr, re.M)
        end = next(i for i, (_, ind, n) in enumerate(rows) if not ind and n == module)
        start = max((i for i, (_, ind, _) in enumerate(rows[:end]) if not ind), default=-1)
        total = int(rows[end][0]) / 1e6
        children = [(int(c), n) for c, ind, n in rows[start + 1 : end] if len(ind) == 2]
        inner = sorted(children, reverse=True)[:4]
        tops = ", ".join(f"{n} {c / 1e6:.3f}" for c, n in inner)
        print(f"  import {module}: {total:.3f} s (largest: {tops})")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="one repeat")
    args = ap.parse_args()
    reps = 1 if args.quick else 5
    urdf = ROOT / "urdf" / "standalone_arm.urdf"
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        ENV["PYTHONPYCACHEPREFIX"] = str(Path(tmp) / "pycache")
        # each side reads the trajectory of the run it times: 120 s (121 points) for the
        # whole-process comparison, 900 s (901 points) for the memory run
        files = {}
        for secs in (WHOLE_S, MEMORY_S):
            files[secs] = Path(tmp) / f"pick_{secs:g}s.yaml"
            files[secs].write_text(trajectory(secs)[0], encoding="utf-8")
        knots = trajectory(WHOLE_S)[1]
        script = Path(tmp) / "mujoco_pd.py"
        script.write_text(MUJOCO_SCRIPT.format(dt=DT, kp=KP, kd=KD, knots=knots), "utf-8")

        def armcli(secs: float, *extra: str, traj: float = WHOLE_S) -> list[str]:
            return [
                str(BIN / "armcli"), "simulate", "--urdf", str(urdf),
                "--trajectory", str(files[traj]), "--dt", str(DT), "--duration", str(secs),
                "--kp", str(KP), "--kd", str(KD), *extra,
            ]  # fmt: skip

        def mujoco(secs: float) -> list[str]:
            return [sys.executable, str(script), str(urdf), str(secs)]

        whole_process(reps, armcli, mujoco)
        memory(armcli, Path(tmp) / "states.csv", files[MEMORY_S], urdf)
        startup(reps)
    print(f"load average after: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
