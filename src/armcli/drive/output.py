"""A drive run's results: the arm's `SimResult`, the tip-over verdict, the states-file columns.

The arm's part is a `SimResult` like the fixed-base engine's, so its summary table, its
tracking plot rows and its joint-state columns are the same code. The states file adds
the base's ground truth (`base.x/y/z/roll/pitch/yaw`: the root link in the world), the
plugin's odometry (`odom.x/y/yaw`), the wheel joints' position/velocity/effort and the
normal force on each ground-contact link (`LINK.normal_force`, the mean over the output
period: MuJoCo's contact force of a single step chatters, drive.model).
The MCAP file: drive.bag; the plot: drive.plot.
"""

from __future__ import annotations

import numpy as np

from armcli.analysis.liftoff import TiltVerdict, verdict
from armcli.drive.job import DriveRun
from armcli.robot.frames import quaternion_rpy
from armcli.sim.rollout import Stats
from armcli.sim.simulate import SETTLE_TOL, SimResult
from armcli.sim.states import column, distinct, sample_states, sample_steps

STOP_TOL = 1e-9  # [rad or m] a joint beyond its range by more is on its (soft) stop


def arm_result(run: DriveRun, keep: np.ndarray) -> SimResult:
    """The arm's motion at the steps `keep`, with statistics over every step."""
    job, L, s = run.job, run.job.model.layout, run.sensors
    arm = job.arm.robot
    q, v, tau = s[:, L.arm_pos], s[:, L.arm_vel], s[:, L.arm_force]
    e = q - run.q_ref
    out = np.abs(e) > SETTLE_TOL
    last_out = np.where(out.any(axis=0), len(e) - 1 - np.argmax(out[::-1], axis=0), -1)
    saturated = np.abs(tau) >= arm.effort * (1.0 - 1e-9)
    stop = (q < arm.lower - STOP_TOL) | (q > arm.upper + STOP_TOL)
    rises = np.sum(
        np.diff(np.vstack([np.zeros((1, q.shape[1]), bool), stop]).astype(int), axis=0) == 1, axis=0
    )
    stats = Stats(
        len(e),
        np.sum(e * e, axis=0),
        np.max(np.abs(e), axis=0),
        e[-1],
        last_out,
        np.sum(saturated[:-1], axis=0),
        rises,
    )
    k = distinct(keep)
    return SimResult(
        arm.names,
        run.steps,
        job.dt,
        job.arm.config.integrator,
        k,
        run.t[k],
        q[k],
        v[k],
        run.q_ref[k],
        run.v_ref[k],
        tau[k],
        saturated[k],
        stop[k],
        stats,
        SETTLE_TOL,
        run.wall_time,
    )


def tip_verdict(run: DriveRun) -> TiltVerdict:
    """The run's tilt and lift-offs (analysis.liftoff)."""
    job, L, s = run.job, run.job.model.layout, run.sensors
    z = s[:, L.contact_pos][:, 2::3]
    force = s[:, L.touch]
    contacts = {link: (force[:, i], z[:, i]) for i, link in enumerate(job.model.contacts)}
    start = dict(zip(job.arm.robot.names, job.arm.q0, strict=True))
    return verdict(job.stance, start, run.t, s[:, L.base_quat], contacts)


def columns(run: DriveRun, res: SimResult, rate: float) -> dict[str, np.ndarray]:
    """The states file's columns at `rate` [Hz]: the arm's, then the drive's."""
    job, L, s = run.job, run.job.model.layout, run.sensors
    cols = sample_states(res, rate)
    k = sample_steps(run.steps, job.dt, rate)
    roll, pitch, yaw = quaternion_rpy(s[:, L.base_quat])
    pos = s[:, L.base_pos]
    base = {
        "x": pos[:, 0],
        "y": pos[:, 1],
        "z": pos[:, 2] - job.model.base_z,
        "roll": roll,
        "pitch": pitch,
        "yaw": yaw,
    }
    cols.update({f"base.{n}": v[k] for n, v in base.items()})
    o = run.odometry
    cols.update({"odom.x": o.x[k], "odom.y": o.y[k], "odom.yaw": o.yaw[k]})
    wheels = (job.params.left_joint, job.params.right_joint)
    for i, w in enumerate(wheels):
        for field, sl in (
            ("position", L.wheel_pos),
            ("velocity", L.wheel_vel),
            ("effort", L.wheel_force),
        ):
            cols[column(w, field)] = s[k, sl][:, i]
    force = _period_mean(s[:, L.touch], k)
    for i, link in enumerate(job.model.contacts):
        cols[f"{link}.normal_force"] = force[:, i]
    return cols


def _period_mean(x: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Per sample k_j, the mean of rows (k_{j-1}, k_j] (the first sample: row k_0 itself)."""
    c = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)])
    prev = np.concatenate([[k[0] - 1], k[:-1]])
    out: np.ndarray = (c[k + 1] - c[prev + 1]) / np.maximum(k - prev, 1)[:, None]
    return out


def plot_steps_of(run_steps: int, dt: float, rate: float) -> np.ndarray:
    """The arm result's kept steps: the output rate's, the plot's and the last."""
    from armcli.sim.plot import plot_steps

    return distinct(
        np.concatenate([sample_steps(run_steps, dt, rate), plot_steps(run_steps), [run_steps]])
    )
