"""Put a simulation together from user inputs: spec or URDF, joints, gains, trajectory.

The CLI only parses options and prints; everything that decides what is simulated
(model, start state, gains, reference, duration, tool point) is here so tests can run it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from armcli.defaults import DEFAULT_DT, DEFAULT_STATE_RATE_HZ, STANDALONE_ARM_URDF
from armcli.errors import InputError
from armcli.robot.file import robot_of
from armcli.robot.frames import pose_matrix
from armcli.robot.mimic import Mimic
from armcli.robot.model import Robot
from armcli.sim.options import SimOptions
from armcli.sim.plot import plot_steps
from armcli.sim.simulate import (
    MAX_STEPS,
    SimConfig,
    SimResult,
    check_stability,
    simulate,
    simulated,
    steps_of,
)
from armcli.sim.states import distinct, sample_steps
from armcli.spec.types import time_step
from armcli.trajectory.message import Trajectory, load_trajectory, loads_trajectory
from armcli.trajectory.reference import Reference, build_reference, coupled
from armcli.urdf.doc import Urdf
from armcli.urdf.source import RobotFile

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

SETTLE_EXTRA_S = 2.0  # [s] simulated after the last trajectory point by default
ARM_URDF = STANDALONE_ARM_URDF
HOLD = "<the start pose>"  # the source of the trajectory a held arm tracks (`prepare(hold=)`)
RATE_SLACK = 1e-9  # relative: --rate 1000 with dt 0.001 is exactly one sample per step


@dataclass(frozen=True)
class SimJob:
    """Everything one simulation run needs, as `prepare` decided it from the user inputs."""

    robot: Robot  # the simulated joints movable, the others locked; its tool point reported
    trajectory: Trajectory
    reference: Reference
    q0: np.ndarray
    duration: float
    config: SimConfig
    tool_label: str  # the tool point and the frame it is reported in
    rate: float  # [Hz] joint_state_publisher rate
    T_frame_root: np.ndarray  # 4x4 pose of the arm's root link in the reporting frame
    notes: tuple[str, ...] = ()  # what reading a xacro --urdf reported (Urdf.notes)
    urdf: Urdf | None = None  # the simulated description (an MCAP's /robot_description, /tf)


def mimic_pairs(
    couplings: Sequence[Mimic], robot: Robot, traj: Trajectory, source: str
) -> list[tuple[int, int, Mimic]]:
    """(follower, leader) model indices of the simulated mimic joints, leaders first.

    A follower is commanded through its leader (multiplier * leader + offset), as
    gazebo_ros2_control and MoveIt do; naming it in the trajectory, or locking its leader
    while it moves, is refused.
    """
    names = list(robot.names)
    out = []
    for m in couplings:  # the whole robot's, some perhaps locked in `robot`
        if m.follower not in names:
            continue  # locked
        if m.follower in traj.joint_names:
            raise InputError(
                f"joint {m.follower!r} mimics {m.leader!r}: command {m.leader!r} and "
                f"{m.follower!r} follows it (multiplier {m.multiplier:g}, offset {m.offset:g})",
                file=source,
                field="joint_names",
            )
        if m.leader not in names:
            raise InputError(
                f"joint {m.follower!r} mimics {m.leader!r}, which is locked: lock "
                f"{m.follower!r} too",
                field="SimOptions.joints",
            )
        out.append((names.index(m.follower), names.index(m.leader), m))
    return out


def _gains(
    robot: Robot,
    spec: RobotSpec | None,
    override: Sequence[float] | None,
    which: str,
    leaders: dict[str, str] | None = None,
) -> np.ndarray:
    n = len(robot.names)
    if override:
        if len(override) not in (1, n):
            raise InputError(
                f"give 1 or {n} value(s), got {len(override)}", field=f"SimOptions.{which}"
            )
        vals = np.array(list(override) * (n if len(override) == 1 else 1), dtype=np.float64)
        if not np.all(np.isfinite(vals)) or np.any(vals < 0.0):
            raise InputError("gains must be finite and >= 0", field=f"SimOptions.{which}")
        return vals
    gains = dict(spec.control.gains) if spec is not None else {}
    for follower, leader in (leaders or {}).items():  # a mimic joint without its own gains
        if follower not in gains and leader in gains:  # is driven like its leader
            gains[follower] = gains[leader]
    followers = leaders or {}  # given through their leaders, never on their own
    missing = [j for j in robot.names if j not in gains and j not in followers]
    if missing:
        raise InputError(
            f"no {which} for {', '.join(missing)} in the spec's control.gains; "
            f"give `SimOptions.{which}`",
            field=f"SimOptions.{which}",
        )
    return np.array([getattr(gains[j], which) for j in robot.names], dtype=float)


def _refuse_integral_gain(robot: Robot, spec: RobotSpec | None) -> None:
    """The simulator runs PD: a spec ki would be silently dropped, so it is refused instead."""
    gains = spec.control.gains if spec is not None else {}
    for j in robot.names:
        if j in gains and gains[j].ki > 0.0:
            raise InputError(
                f"= {gains[j].ki:g}: armcli simulates PD control only (no integral term); "
                "set ki to 0 to simulate this spec, or give --kp and --kd explicitly",
                field=f"control.gains.{j}.ki",
            )


def _report_frame(robot: Robot, spec: RobotSpec | None) -> tuple[str, np.ndarray]:
    """How the tool point is reported ("tool in frame"), and the arm root's pose in that frame.

    With a spec that mounts the arm on a mobile base, the frame is the base's root link
    (base_footprint), composed from the fixed joint origins (moving joints at 0),
    so the numbers match `check` and `view`; otherwise the arm's own root link.
    InputError (before the run) for a URDF without a link to report.
    """
    model, _ = robot.model, robot.tool_frame
    tool = str(robot.tool.label if robot.tool is not None else "")
    root = next(f.name for f in model.frames if f.parentJoint == 0 and f.name != "universe")
    T = np.eye(4)
    if spec is None or spec.mounted_base() is None:
        return f"{tool} in {root}", T
    by_child = {j.child: j for j in spec.all_joints().values()}
    link = spec.arm_root()
    while link in by_child:
        joint = by_child[link]
        T = pose_matrix(joint.origin.xyz, joint.origin.rpy) @ T
        link = joint.parent
    return f"{tool} in {link}", T


def start_state(robot: Robot, spec: RobotSpec | None) -> np.ndarray:
    """The spec's `home` pose (clamped into the joint limits); a joint it leaves out rests.

    Without a `home` pose every joint rests (`Robot.rest`: 0, else the middle of its range).
    """
    home = spec.pose("home") if spec is not None and "home" in spec.poses else {}
    q = np.array([home.get(j, robot.rest(j)) for j in robot.names], dtype=float)
    return np.asarray(np.clip(q, robot.lower, robot.upper), dtype=float)


def _within(traj: Trajectory, limits: dict[str, tuple[float, float]]) -> Trajectory:
    """A trajectory handed over as an object, refused (InputError) where a file would be.

    Unknown joints and positions outside the limits; the caller built it from this robot.
    """
    for i, name in enumerate(traj.joint_names):
        if name not in limits:
            raise InputError(
                f"unknown joint {name!r}; valid: {', '.join(limits)}",
                file=traj.source,
                field="joint_names",
            )
        lo, hi = limits[name]
        if not np.all((traj.positions[:, i] >= lo) & (traj.positions[:, i] <= hi)):
            raise InputError(
                f"{name} leaves its range [{lo:g}, {hi:g}]", file=traj.source, field="positions"
            )
    return traj


def _duration_and_rate(
    spec: RobotSpec | None, opts: SimOptions, t_last: float, dt: float
) -> tuple[float, float]:
    """Simulated time [s] (default: the last point + settle time) and output rate [Hz], bounded."""
    rate = opts.rate
    total = opts.duration if opts.duration is not None else t_last + SETTLE_EXTRA_S
    if not (np.isfinite(total) and 0 < total <= 3600):
        raise InputError(f"must be in (0, 3600] s, got {total:g}", field="SimOptions.duration")
    if total / dt > MAX_STEPS:
        raise InputError(
            f"{total:g} s at dt = {dt:g} s is {total / dt:.3g} steps, more than {MAX_STEPS:,}; "
            "shorten `SimOptions.duration` or raise `SimOptions.dt`",
            field="SimOptions.duration",
        )
    jsp = spec.arm.joint_state_publisher if spec is not None else None
    rate = (
        rate
        if rate is not None
        else (jsp.update_rate if jsp is not None else DEFAULT_STATE_RATE_HZ)
    )
    if not (np.isfinite(rate) and 0 < rate <= (1.0 + RATE_SLACK) / dt):
        raise InputError(
            f"must be in (0, 1/dt = {1.0 / dt:g}] Hz (one state per time step at most), "
            f"got {rate:g}",
            field="SimOptions.rate",
        )
    return float(total), float(rate)


def base_joints(spec: RobotSpec | None) -> dict[str, str]:
    """The mobile base's joints by name, with what they are (a trajectory may not name them)."""
    if spec is None or spec.mobile_base is None:
        return {}
    return {
        name: "a wheel joint of the mobile base"
        if j.type == "continuous"
        else "a mobile-base joint"
        for name, j in spec.mobile_base.joints.items()
    }


def prepare(
    file: RobotFile,
    opts: SimOptions,
    *,
    gate: Callable[[Urdf], None] | None = None,
    hold: bool = False,
) -> SimJob:
    """Validate every input and assemble the run; raises InputError on bad input.

    What runs is `file.arm` (a spec's standalone arm, or a URDF file) with the file's
    spec's settings (gains, dt, home). `gate` sees a URDF file (`--urdf`) before it is
    simulated and may refuse it (the simulate command passes check.gate.refuse_check_errors).
    `hold`: without a trajectory the arm holds its start pose (the drive's arm).
    """
    spec, dt = file.spec, opts.dt
    if not (hold and opts.trajectory is None and opts.message is None):
        _one_trajectory(opts)
    dt_field = "SimOptions.dt" if dt is not None else "control.dt"  # else the spec's, checked
    dt = dt if dt is not None else (spec.control.dt if spec is not None else DEFAULT_DT)
    dt = time_step(dt, dt_field)
    doc = file.arm
    whole = robot_of(file, doc, gate=None if file.compiled else gate)
    robot = simulated(whole, opts.joints)
    traj = _trajectory(robot, spec, opts)
    pairs = mimic_pairs(whole.mimics, robot, traj, traj.source)
    q0 = start_state(robot, spec)
    for f, lead, m in pairs:
        q0[f] = np.clip(m.position(q0[lead]), robot.lower[f], robot.upper[f])
    ref = coupled(build_reference(traj, robot.names, q0), pairs)
    gc = (
        opts.gravity_comp
        if opts.gravity_comp is not None
        else bool(spec and spec.control.gravity_compensation)
    )
    leaders = {m.follower: m.leader for _, _, m in pairs}
    kp = _gains(robot, spec, opts.kp, "kp", leaders)
    kd = _gains(robot, spec, opts.kd, "kd", leaders)
    if opts.kp is None or opts.kd is None:
        _refuse_integral_gain(robot, spec)
    cfg = SimConfig(kp, kd, dt, opts.integrator, gc)
    configs = np.vstack([q0[None, :], ref.sample(traj.times)[0]])
    check_stability(robot, cfg, configs)
    total, rate = _duration_and_rate(spec, opts, traj.duration, dt)
    label, T_frame_root = _report_frame(robot, spec)
    return SimJob(
        robot, traj, ref, q0, total, cfg, label, float(rate), T_frame_root, doc.notes, doc
    )


def _one_trajectory(opts: SimOptions) -> None:
    if (opts.trajectory is None) == (opts.message is None):
        raise InputError(
            "give exactly one of `SimOptions.trajectory` (a file) or `SimOptions.message`",
            field="SimOptions.trajectory",
        )


def _trajectory(robot: Robot, spec: RobotSpec | None, opts: SimOptions) -> Trajectory:
    """What the arm tracks: a file, a message, a `Trajectory` handed over, else its start.

    The start pose held is built here as an object (the drive without a trajectory), not
    written as YAML text and read back.
    """
    trajectory, message = opts.trajectory, opts.message
    if trajectory is None and message is None:
        q0 = start_state(robot, spec)
        return Trajectory(robot.names, np.zeros(1), q0[None, :], None, None, source=HOLD)
    limits = {
        n: (float(lo), float(hi))
        for n, lo, hi in zip(robot.names, robot.lower, robot.upper, strict=True)
    }
    if isinstance(trajectory, Trajectory):
        return _within(trajectory, limits)
    others = base_joints(spec)
    if trajectory is not None:
        return load_trajectory(trajectory, limits, clamp=opts.clamp, others=others)
    return loads_trajectory(
        str(message), limits, source="SimOptions.message", clamp=opts.clamp, others=others
    )


def tool_position(job: SimJob, q: np.ndarray) -> np.ndarray:
    """End-effector point in the reporting frame (see `_report_frame`) at configuration q [m]."""
    p_root = job.robot.tool_position(job.robot.q(q))
    out: np.ndarray = job.T_frame_root[:3, :3] @ p_root + job.T_frame_root[:3, 3]
    return out


def run(
    job: SimJob,
    progress: Callable[[int, int], None] | None = None,
    *,
    plot: bool = False,
    extra: Callable[[int], np.ndarray] | None = None,
) -> SimResult:
    """Run the job, keeping the states at the output rate (and those a plot draws).

    `progress(steps_done, steps_total)` is called between chunks of steps; `extra(steps)`
    names more steps to keep (the zero-moment point's, sim.tipping).
    """
    steps = steps_of(job.duration, job.config.dt)
    # the output rate's states, the final one (the end effector is reported there), a plot's
    keep = np.concatenate([sample_steps(steps, job.config.dt, job.rate), [steps]])
    if plot:
        keep = np.concatenate([keep, plot_steps(steps)])
    if extra is not None:
        keep = np.concatenate([keep, extra(steps)])
    keep = distinct(keep)
    return simulate(
        job.robot, job.reference, job.q0, job.duration, job.config, progress, record=keep
    )
