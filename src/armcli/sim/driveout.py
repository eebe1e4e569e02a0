"""A drive run's outputs: the arm's result, the states-file columns, the MCAP topics, the plot.

The arm's part is a `SimResult` like the fixed-base engine's, so its summary table, its
tracking plot rows and its joint-state columns are the same code. The states file adds
the base's ground truth (`base.x/y/z/roll/pitch/yaw`: the root link in the world), the
plugin's odometry (`odom.x/y/yaw`), the wheel joints' position/velocity/effort and the
normal force on each ground-contact link (`LINK.normal_force`, the mean over the output
period: MuJoCo's contact force of a single step chatters, sim.drivemodel).

MCAP: /joint_states with the wheels, /odom (nav_msgs/msg/Odometry, encoder odometry as
the plugin publishes it at each output time), /cmd_vel (geometry_msgs/msg/Twist at each
command's time) and /tf with `odom -> base` and `world -> odom`: the drift a perfect
localiser would remove, so that `world -> base` is the ground truth (as map -> odom in ROS).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from armcli.sim import rosbag
from armcli.sim.diffdrive import yaw_quaternion
from armcli.sim.drive import DriveRun
from armcli.sim.liftoff import TipVerdict, roll_pitch_yaw, verdict
from armcli.sim.rollout import Stats
from armcli.sim.simulate import SETTLE_TOL, SimResult
from armcli.sim.states import TIME, column, distinct, sample_states, sample_steps

WORLD = rosbag.WORLD
ODOMETRY = "nav_msgs/msg/Odometry"
TWIST = "geometry_msgs/msg/Twist"
ODOM, CMD_VEL = "/odom", "/cmd_vel"
STOP_TOL = 1e-9  # [rad or m] a joint beyond its range by more is on its (soft) stop
# the plugin's covariance (x, y, yaw), its defaults; 1e12 for the unobserved z, roll, pitch
COVARIANCE = {0: 1e-5, 7: 1e-5, 14: 1e12, 21: 1e12, 28: 1e12, 35: 1e-3}


def arm_result(run: DriveRun, keep: np.ndarray) -> SimResult:
    """The arm's motion at the steps `keep`, with statistics over every step."""
    job, L, s = run.job, run.job.model.layout, run.sensors
    arm = job.arm.arm
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
        arm.joint_names,
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


def tip_verdict(run: DriveRun) -> TipVerdict:
    """The run's tilt and lift-offs (sim.liftoff)."""
    job, L, s = run.job, run.job.model.layout, run.sensors
    z = s[:, L.contact_pos][:, 2::3]
    force = s[:, L.touch]
    contacts = {link: (force[:, i], z[:, i]) for i, link in enumerate(job.model.contacts)}
    start = dict(zip(job.arm.arm.joint_names, job.arm.q0, strict=True))
    return verdict(job.stance, start, run.t, s[:, L.base_quat], contacts)


def columns(run: DriveRun, res: SimResult, rate: float) -> dict[str, np.ndarray]:
    """The states file's columns at `rate` [Hz]: the arm's, then the drive's."""
    job, L, s = run.job, run.job.model.layout, run.sensors
    cols = sample_states(res, rate)
    k = sample_steps(run.steps, job.dt, rate)
    roll, pitch, yaw = roll_pitch_yaw(s[:, L.base_quat])
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


def mcap_bytes(run: DriveRun, cols: dict[str, np.ndarray], rate: float) -> bytes:
    """The run as rosbag2 MCAP bytes (sim.rosbag's topics plus the drive's)."""
    job = run.job
    wheels = [job.params.left_joint, job.params.right_joint]
    chans = rosbag.channels(cols, [*job.arm.arm.joint_names, *wheels], job.robot)
    stamps = [round(float(t) * 1e9) for t in cols[TIME]]
    extra = _base_transforms(job.params.odom_frame, job.params.base_frame, cols, stamps)
    chans = [
        rosbag.Channel(
            c.topic,
            c.datatype,
            c.qos,
            [
                (ns, {"transforms": [*extra[i], *m["transforms"]]})
                for i, (ns, m) in enumerate(c.messages)
            ],
        )
        if c.topic == rosbag.TF
        else c
        for c in chans
    ]
    k = sample_steps(run.steps, job.dt, rate)
    chans.append(rosbag.Channel(ODOM, ODOMETRY, rosbag.qos(10, False), _odometry(run, k, stamps)))
    chans.append(rosbag.Channel(CMD_VEL, TWIST, rosbag.qos(10, False), _cmd_vel(run)))
    return rosbag.mcap_bytes(chans)


def _tf(parent: str, child: str, ns: int, xyz: Any, quat: Sequence[float]) -> Any:
    return {
        "header": {"stamp": rosbag.stamp(ns), "frame_id": parent},
        "child_frame_id": child,
        "transform": {
            "translation": dict(zip("xyz", map(float, xyz), strict=True)),
            "rotation": dict(zip("xyzw", map(float, quat), strict=True)),
        },
    }


def _base_transforms(
    odom: str, base: str, cols: dict[str, np.ndarray], stamps: list[int]
) -> list[list[Any]]:
    """Per output time: world -> odom (truth composed with odometry's inverse), odom -> base."""
    out = []
    for i, ns in enumerate(stamps):
        T_odom_base = _pose(
            cols["odom.x"][i], cols["odom.y"][i], 0.0, 0.0, 0.0, cols["odom.yaw"][i]
        )
        T_world_base = _pose(
            *(cols[f"base.{n}"][i] for n in ("x", "y", "z", "roll", "pitch", "yaw"))
        )
        T_world_odom = T_world_base @ np.linalg.inv(T_odom_base)
        out.append(
            [
                _tf(WORLD, odom, ns, T_world_odom[:3, 3], _quat(T_world_odom[:3, :3])),
                _tf(odom, base, ns, T_odom_base[:3, 3], yaw_quaternion(float(cols["odom.yaw"][i]))),
            ]
        )
    return out


def _pose(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    T = np.eye(4)
    q = rosbag.quat_rpy((roll, pitch, yaw))
    T[:3, :3] = _matrix(q)
    T[:3, 3] = (x, y, z)
    return T


def _matrix(q: np.ndarray) -> np.ndarray:
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _quat(R: np.ndarray) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation matrix (Shepperd's method, w >= 0)."""
    w = 0.5 * np.sqrt(max(1.0 + R[0, 0] + R[1, 1] + R[2, 2], 0.0))
    if w > 1e-6:
        return (
            (R[2, 1] - R[1, 2]) / (4 * w),
            (R[0, 2] - R[2, 0]) / (4 * w),
            (R[1, 0] - R[0, 1]) / (4 * w),
            w,
        )
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    v = np.zeros(3)
    v[i] = 0.5 * np.sqrt(max(1.0 + R[i, i] - R[j, j] - R[k, k], 0.0))
    v[j] = (R[j, i] + R[i, j]) / (4 * v[i])
    v[k] = (R[k, i] + R[i, k]) / (4 * v[i])
    return float(v[0]), float(v[1]), float(v[2]), float((R[k, j] - R[j, k]) / (4 * v[i]))


def _odometry(run: DriveRun, k: np.ndarray, stamps: list[int]) -> list[Any]:
    p, o = run.job.params, run.odometry
    cov = [COVARIANCE.get(i, 0.0) for i in range(36)]
    zero = {"x": 0.0, "y": 0.0, "z": 0.0}
    out = []
    for i, ns in enumerate(stamps):
        j = int(k[i])
        qx, qy, qz, qw = yaw_quaternion(float(o.yaw[j]))
        out.append(
            (
                ns,
                {
                    "header": {"stamp": rosbag.stamp(ns), "frame_id": p.odom_frame},
                    "child_frame_id": p.base_frame,
                    "pose": {
                        "pose": {
                            "position": {"x": float(o.x[j]), "y": float(o.y[j]), "z": 0.0},
                            "orientation": {"x": qx, "y": qy, "z": qz, "w": qw},
                        },
                        "covariance": cov,
                    },
                    "twist": {
                        "twist": {
                            "linear": {**zero, "x": float(o.linear[j])},
                            "angular": {**zero, "z": float(o.angular[j])},
                        },
                        "covariance": cov,
                    },
                },
            )
        )
    return out


def _cmd_vel(run: DriveRun) -> list[Any]:
    cmd, end = run.job.cmd, run.t[-1]
    out = []
    for t, lin, ang in zip(cmd.times, cmd.linear, cmd.angular, strict=True):
        if t <= end:
            out.append(
                (
                    round(float(t) * 1e9),
                    {
                        "linear": dict(zip("xyz", map(float, lin), strict=True)),
                        "angular": dict(zip("xyz", map(float, ang), strict=True)),
                    },
                )
            )
    return out


def plot_png(run: DriveRun, res: SimResult, verdict_: TipVerdict) -> bytes:
    """The tracking plot with two more rows: the path seen from above, the wheel loads."""
    from armcli.sim.plot import tracking_png

    title = f"armcli simulate --cmd-vel (MuJoCo, dt = {res.dt:g} s)"
    return tracking_png(res, run.job.arm.arm.effort, _drive_rows(run, verdict_), 2, title)


LOAD_WINDOW_S = 0.01  # [s] the wheel loads are drawn as means over this (a single step chatters)


def _drive_rows(run: DriveRun, verdict_: TipVerdict) -> Callable[[Sequence[Any]], None]:
    job, L, s = run.job, run.job.model.layout, run.sensors
    step = max(1, run.steps // 4000)
    window = max(1, round(LOAD_WINDOW_S / job.dt))

    def wide(row: Sequence[Any]) -> Any:
        """One axes across the figure in place of a row's per-joint axes."""
        spec = row[0].get_subplotspec()
        grid, fig = spec.get_gridspec(), row[0].figure
        for a in row:
            a.remove()
        return fig.add_subplot(grid[spec.rowspan.start, :])

    def draw(axes: Sequence[Any]) -> None:
        half = len(axes) // 2
        ax, load = wide(axes[:half]), wide(axes[half:])
        pos = s[::step, L.base_pos]
        ax.plot(pos[:, 0], pos[:, 1], color="C0", lw=1.5, label=f"truth ({job.params.base_frame})")
        ax.plot(run.odometry.x[::step], run.odometry.y[::step], "--", color="C1", lw=1.2,
                label="odometry (wheel encoders)")  # fmt: skip
        ax.plot(pos[0, 0], pos[0, 1], "o", color="k", ms=4, label="start")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title("path seen from above", fontsize=11)
        ax.legend(loc="best", fontsize=8)
        ax.grid(True, alpha=0.3)
        n = (len(s) // window) * window
        t = run.t[:n].reshape(-1, window).mean(axis=1)
        force = s[:n, L.touch].reshape(-1, window, len(job.model.contacts)).mean(axis=1)
        for i, link in enumerate(job.model.contacts):
            load.plot(t, force[:, i], lw=1.0, label=link)
        for lift in verdict_.lifts:
            load.axvspan(lift.start, lift.start + lift.duration, color="C3", alpha=0.25)
        load.set_xlabel("time [s]")
        load.set_ylabel("normal force [N]")
        load.set_title(f"wheel and caster loads ({LOAD_WINDOW_S * 1e3:g} ms means; shaded: "
                       "lift-off)", fontsize=11)  # fmt: skip
        load.legend(loc="best", fontsize=8)
        load.grid(True, alpha=0.3)

    return draw


def plot_steps_of(run_steps: int, dt: float, rate: float) -> np.ndarray:
    """The arm result's kept steps: the output rate's, the plot's and the last."""
    from armcli.sim.plot import plot_steps

    return distinct(
        np.concatenate([sample_steps(run_steps, dt, rate), plot_steps(run_steps), [run_steps]])
    )
