"""What a trajectory asks of the arm that it cannot do, said before any simulated verdict.

A reference faster than a joint's velocity limit, or a pose whose gravity torque exceeds a
joint's effort limit, makes every later number (tracking errors, a zero-moment point metres
outside the polygon, "the robot tips over") a consequence, not the cause. `simulate`
refuses the first (the trajectory's times are wrong) and warns of the second (the motor
saturates: the arm sags, as it would) before it runs.
"""

from __future__ import annotations

import math

import numpy as np

from armcli.sim.job import SimJob

SPEED_SAMPLES = 64  # per segment: the cubic/quintic reference's peak speed, within 0.1 %
SPEED_TOL = 1e-9  # relative slack over a velocity or effort limit


def _point_at(job: SimJob, t: float) -> int:
    """The trajectory point reached at time `t` (a segment's end)."""
    return int(np.argmin(np.abs(job.trajectory.times - t)))


def speed_problems(job: SimJob) -> list[str]:
    """One line per joint whose reference outruns its velocity limit (first segment only)."""
    ref, robot = job.reference, job.robot
    out: list[str] = []
    said: set[int] = set()
    for s in range(len(ref.knots) - 1):
        a, b = float(ref.knots[s]), float(ref.knots[s + 1])
        if b <= a:
            continue
        _, v = ref.sample(np.linspace(a, b, SPEED_SAMPLES, endpoint=False))
        peak = np.max(np.abs(v), axis=0)
        for j, name in enumerate(robot.names):
            vmax = float(robot.velocity[j])
            if j in said or not (math.isfinite(vmax) and vmax > 0):
                continue
            if peak[j] > vmax * (1 + SPEED_TOL):
                said.add(j)
                k = _point_at(job, b)
                out.append(
                    f"{job.trajectory.source} points[{k}]: {name} moves at up to "
                    f"{peak[j]:.4g} rad/s from t = {a:g} s to {b:g} s, above its velocity limit "
                    f"{vmax:g} rad/s; give that segment at least {(b - a) * peak[j] / vmax:.3g} s "
                    "(time_from_start)"
                )
    return out


def holding_problems(job: SimJob) -> list[str]:
    """One line per joint whose effort limit cannot hold the arm against gravity at a point."""
    robot = job.robot
    times = np.concatenate(([0.0], job.trajectory.times))
    q_ref, _ = job.reference.sample(times)
    worst = np.zeros(len(robot.names))
    where = np.zeros(len(robot.names), dtype=int)
    for k, q in enumerate(q_ref):
        g = np.abs(robot.gravity(robot.q(q)))
        better = g > worst
        worst, where = np.where(better, g, worst), np.where(better, k, where)
    out = []
    for j, name in enumerate(robot.names):
        effort = float(robot.effort[j])
        if math.isfinite(effort) and worst[j] > effort * (1 + SPEED_TOL):
            at = "the start" if where[j] == 0 else f"points[{where[j] - 1}]"
            out.append(
                f"{job.trajectory.source} {at}: {name} needs {worst[j]:.3g} N·m to hold the arm "
                f"against gravity, above its effort limit {effort:g} N·m: the motor saturates "
                "and the arm sags, whatever the gains (raise the effort limit; armcli check: "
                "gravity-effort)"
            )
    return out
