"""Benchmark: `armcli simulate SPEC --cmd-vel` (30 s drive, arm moving) vs a bare MuJoCo loop.

Each side a fresh process as a user runs it, in turn (A B A B ...), CPU seconds from the
kernel's accounting (wait4), the ratio taken pair by pair:

- armcli: the course robot (specs/my_robot.yaml) driving 30 s of /cmd_vel commands
  (forward, turn, forward, ... at the plugin's 1 m/s² ramps) while its arm runs 30 s of
  pick cycles, at the spec's dt = 1 ms (30,000 steps): spec compile, check gate, model
  export and compile, the run with its diff-drive controller, odometry and verdict;
  without output, and writing the MCAP;
- peer: a Python script loading the exported model (`armcli export mjcf --whole-robot
  --base free`, its scene.xml with the floor) and calling mujoco.mj_step 30,000 times.

Targets (issue 30): armcli <= 1.5x the peer's CPU, and >= 50x faster than real time.
The real-time factor is given for the whole process (wall) and for the stepping alone
(the summary's µs/step). Run with `make bench` (or `python bench/bench_drive.py
[--quick]`). Not a test: numbers depend on the machine and its load.
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
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
SPEC = ROOT / "specs" / "my_robot.yaml"
DURATION = 30.0  # [s]
DT = 1e-3  # [s] the spec's control.dt
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
CYCLE = [(0.6, 0.4, 1.0), (0.9, 1.2, 2.0), (0.9, 1.2, 2.5), (0.5, 0.8, 3.5), (0.3, 0.3, 5.0)]
DRIVE = [(0.3, 0.0, 3.0), (0.0, 0.6, 2.5)]  # (linear.x, angular.z, seconds) repeated
BARE = """
import sys
import mujoco
m = mujoco.MjModel.from_xml_path(sys.argv[1])
m.opt.timestep = float(sys.argv[3])
d = mujoco.MjData(m)
for _ in range(round(float(sys.argv[2]) / m.opt.timestep)):
    mujoco.mj_step(m, d)
"""


def arm_trajectory(duration: float) -> str:
    lines = ["joint_names: [arm_base_forearm_joint, forearm_hand_joint]", "points:"]
    for c in range(round(duration / 5.0)):
        for q1, q2, t in CYCLE:
            lines.append(f" - {{positions: [{q1}, {q2}], time_from_start: {5.0 * c + t}}}")
    return "\n".join(lines) + "\n"


def commands(duration: float) -> str:
    lines, t = ["commands:"], 0.5
    while t < duration - 1.0:
        for v, w, hold in DRIVE:
            lines.append(f"  - {{linear: {{x: {v}}}, angular: {{z: {w}}}, time_from_start: {t}}}")
            t += hold
    lines.append(f"  - {{time_from_start: {t}}}")
    return "\n".join(lines) + "\n"


def run_once(cmd: list[str]) -> tuple[float, float, str]:
    """Wall seconds, CPU seconds (user + system) and stdout of one process."""
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=ENV)
    out = proc.stdout.read().decode() if proc.stdout else ""
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"failed: {' '.join(cmd)}")
    return wall, usage.ru_utime + usage.ru_stime, out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="one repeat")
    reps = 1 if ap.parse_args().quick else 5
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        ENV["PYTHONPYCACHEPREFIX"] = str(tmp / "pycache")
        (tmp / "arm.yaml").write_text(arm_trajectory(DURATION))
        (tmp / "drive.yaml").write_text(commands(DURATION))
        (tmp / "bare.py").write_text(BARE)
        subprocess.run([str(BIN / "armcli"), "export", "mjcf", str(SPEC), "--whole-robot",
                        "--base", "free", "-o", str(tmp / "robot.xml")],
                       check=True, capture_output=True, env=ENV)  # fmt: skip
        armcli = [str(BIN / "armcli"), "simulate", str(SPEC), "--cmd-vel", str(tmp / "drive.yaml"),
                  "-t", str(tmp / "arm.yaml"), "--duration", str(DURATION)]  # fmt: skip
        mcap = [*armcli, "-o", str(tmp / "run.mcap")]
        bare = [sys.executable, str(tmp / "bare.py"), str(tmp / "scene.xml"), str(DURATION),
                str(DT)]  # fmt: skip
        # the same processes for one step: their set-up (imports, model), cut to compare
        # the stepping alone
        armcli_setup = [*armcli[:-1], str(DT)]
        bare_setup = [*bare[:-2], str(DT), str(DT)]
        for cmd in (armcli, bare):
            run_once(cmd)  # untimed: fills the bytecode cache
        keys = ("armcli", "bare", "mcap", "armcli_setup", "bare_setup")
        cmds = dict(zip(keys, (armcli, bare, mcap, armcli_setup, bare_setup), strict=True))
        rows: dict[str, list[tuple[float, float, str]]] = {k: [] for k in keys}
        for _ in range(reps):
            for key in keys:
                rows[key].append(run_once(cmds[key]))
    med = statistics.median
    steps = round(DURATION / DT)
    print(f"\n{DURATION:g} s drive of the course robot, arm moving, dt = {DT} s ({steps} steps); "
          f"median of {reps} pairs, CPU seconds of whole processes")  # fmt: skip
    for name, key in (("bare MuJoCo loop (exported model)", "bare"),
                      ("armcli simulate --cmd-vel", "armcli"),
                      ("armcli simulate --cmd-vel -o run.mcap", "mcap")):  # fmt: skip
        cpu, wall = med(r[1] for r in rows[key]), med(r[0] for r in rows[key])
        print(f"  {name:<40} {cpu:6.2f} CPU s  {wall:6.2f} wall s  "
              f"real-time factor {DURATION / wall:5.1f}x")  # fmt: skip
    for key in ("armcli", "mcap"):
        ratio = med(a[1] / b[1] for a, b in zip(rows[key], rows["bare"], strict=True))
        print(f"  {key} / bare, whole process: {ratio:.2f}x (target <= 1.5x)")
    setup = {k: med(r[1] for r in rows[f"{k}_setup"]) for k in ("armcli", "bare")}
    stepping = {k: med(r[1] for r in rows[k]) - setup[k] for k in ("armcli", "bare")}
    print(f"  set-up (the same processes for one step): armcli {setup['armcli']:.2f} CPU s, "
          f"bare {setup['bare']:.2f} CPU s; stepping alone (set-up cut): armcli / bare "
          f"{stepping['armcli'] / stepping['bare']:.2f}x")  # fmt: skip
    per_step = [float(m.group(1)) for r in rows["armcli"]
                if (m := re.search(r"\(([\d.]+) µs/step\)", r[2]))]  # fmt: skip
    if per_step:
        us = med(per_step)
        print(f"  armcli's loop (wall clock, the summary's): {us:.2f} µs/step, real-time "
              f"factor {1e6 * DT / us:.0f}x (target >= 50x)")  # fmt: skip
    cpu_rtf = DURATION / max(stepping["armcli"], 1e-9)
    print(f"  armcli stepping alone in CPU time: real-time factor {cpu_rtf:.0f}x")


if __name__ == "__main__":
    main()
