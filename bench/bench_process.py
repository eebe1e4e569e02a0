"""Benchmark: the whole `armcli simulate` process vs the equivalent MuJoCo script.

A 120 s pick-like trajectory at dt = 0.5 ms (240,000 steps) on the standalone arm, PD
gains Kp 50, Kd 5. Each side runs as a fresh process, as a user would run it; the same
command with a one-step duration measures imports and set-up, which are then cut to give
the stepping cost alone. Run with `make bench` (or `python bench/bench_process.py
[--quick]`). Not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
DT = 5e-4  # [s]
KP, KD = 50.0, 5.0
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


def trajectory(duration: float) -> tuple[str, list[tuple[float, float, float]]]:
    """YAML text and knots (q1, q2, t) of `duration` s of pick cycles from (0.2, 0.2)."""
    knots = [(0.2, 0.2, 0.0)]
    lines = ["joint_names: [arm_base_forearm_joint, forearm_hand_joint]", "points:"]
    for c in range(round(duration / 5.0)):
        for q1, q2, t in CYCLE:
            knots.append((q1, q2, 5.0 * c + t))
            lines.append(f" - {{positions: [{q1}, {q2}], time_from_start: {5.0 * c + t}}}")
    return "\n".join(lines) + "\n", knots


def timed(cmd: list[str], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="one repeat")
    args = ap.parse_args()
    reps = 1 if args.quick else 3
    duration = 120.0
    urdf = ROOT / "urdf" / "standalone_arm.urdf"
    text, knots = trajectory(duration)
    with tempfile.TemporaryDirectory() as tmp:
        traj = Path(tmp) / "long.yaml"
        traj.write_text(text, encoding="utf-8")
        script = Path(tmp) / "mujoco_pd.py"
        script.write_text(MUJOCO_SCRIPT.format(dt=DT, kp=KP, kd=KD, knots=knots), "utf-8")

        def armcli(engine: str, secs: float) -> list[str]:
            return [
                str(BIN / "armcli"), "simulate", "--urdf", str(urdf), "--trajectory", str(traj),
                "--dt", str(DT), "--duration", str(secs), "--kp", str(KP), "--kd", str(KD),
                "--engine", engine,
            ]  # fmt: skip

        def mujoco(secs: float) -> list[str]:
            return [sys.executable, str(script), str(urdf), str(secs)]

        rows = {}
        for name, make in (
            ("MuJoCo script (PD in Python)", mujoco),
            ("armcli simulate, compiled", lambda s: armcli("native", s)),
            ("armcli simulate, Python engine", lambda s: armcli("python", s)),
        ):
            total = timed(make(duration), reps)
            setup = timed(make(DT), reps)
            rows[name] = (total, setup)
    steps = round(duration / DT)
    mj_total, mj_setup = rows["MuJoCo script (PD in Python)"]
    print(f"\nwhole process, {duration:g} s trajectory at dt = {DT} s ({steps} steps)")
    head = ("process", "total [s]", "set-up [s]", "x MuJoCo", "cut x MuJoCo", "µs/step")
    print("  ".join(f"{c:>12}" if i else f"{c:<32}" for i, c in enumerate(head)))
    for name, (total, setup) in rows.items():
        cut = (total - setup) / (mj_total - mj_setup)
        cells = (name, f"{total:.2f}", f"{setup:.2f}", f"{total / mj_total:.3f}", f"{cut:.3f}",
                 f"{(total - setup) / steps * 1e6:.2f}")  # fmt: skip
        print("  ".join(f"{c:>12}" if i else f"{c:<32}" for i, c in enumerate(cells)))


if __name__ == "__main__":
    main()
