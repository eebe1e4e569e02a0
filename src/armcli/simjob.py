"""Put a simulation together from user inputs: spec or URDF, joints, gains, trajectory.

The CLI only parses options and prints; everything that decides what is simulated
(model, start state, gains, reference, duration, tool point) is here so tests can run it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.errors import InputError
from armcli.interpolation import Reference, build_reference
from armcli.sim import Arm, SimConfig, SimResult, arm_from_model, check_stability, simulate
from armcli.trajectory import Trajectory, load_trajectory, loads_trajectory

if TYPE_CHECKING:
    from armcli.urdfdoc import Urdf

SETTLE_EXTRA_S = 2.0  # [s] simulated after the last trajectory point by default
ARM_URDF = "standalone_arm.urdf"
RATE_SLACK = 1e-9  # relative: --rate 1000 with dt 0.001 is exactly one sample per step
MAX_STEPS = 2_000_000  # ~200 MB of recorded states for a 2-joint arm


@dataclass(frozen=True)
class SimJob:
    arm: Arm
    trajectory: Trajectory
    reference: Reference
    q0: np.ndarray
    duration: float
    config: SimConfig
    tool_frame: int  # pinocchio frame id of the end-effector link
    tool_offset: np.ndarray  # [m] point in that frame
    tool_label: str
    rate: float  # [Hz] joint_state_publisher rate
    T_frame_root: np.ndarray  # 4x4 pose of the arm's root link in the reporting frame


def load_arm(
    spec: Any | None,
    urdf: Path | None,
    joints: Sequence[str] | None,
    *,
    trust_xacro: bool = False,
    gate: Callable[[Urdf], None] | None = None,
) -> Arm:
    """The simulated arm: the spec's standalone arm built in memory, or a given URDF.

    A given URDF goes through the same strict reader as `check` (no DOCTYPE, finite
    numbers, no foreign xacro without trust), since Pinocchio alone would simulate
    mass="nan" as 0 kg.
    """
    from armcli.model import load_model

    if urdf is not None:
        from armcli.robot_source import load_checked_model

        loaded = load_checked_model(urdf, trust_xacro=trust_xacro, gate=gate)
        return arm_from_model(loaded.model, joints)
    from armcli.build import expand_urdfs

    if spec is None:
        raise InputError("give a spec or --urdf", field="--urdf")
    xml = expand_urdfs(spec)[ARM_URDF].decode("utf-8")
    return arm_from_model(load_model(ARM_URDF, xml=xml).model, joints)


def _gains(arm: Arm, spec: Any | None, override: Sequence[float] | None, which: str) -> np.ndarray:
    n = len(arm.joint_names)
    if override:
        if len(override) not in (1, n):
            raise InputError(f"give 1 or {n} value(s), got {len(override)}", field=f"--{which}")
        vals = np.array(list(override) * (n if len(override) == 1 else 1), dtype=np.float64)
        if not np.all(np.isfinite(vals)) or np.any(vals < 0.0):
            raise InputError("gains must be finite and >= 0", field=f"--{which}")
        return vals
    gains = spec.control.gains if spec is not None else {}
    missing = [j for j in arm.joint_names if j not in gains]
    if missing:
        raise InputError(
            f"no {which} for {', '.join(missing)} in the spec; give --{which}", field=f"--{which}"
        )
    return np.array([getattr(gains[j], which) for j in arm.joint_names], dtype=float)


def _tool(arm: Arm, spec: Any | None) -> tuple[int, np.ndarray, str]:
    model = arm.model
    if spec is not None and spec.arm.tool is not None and model.existFrame(spec.arm.tool.link):
        off = np.array(spec.arm.tool.xyz, dtype=float)
        return model.getFrameId(spec.arm.tool.link), off, f"{spec.arm.tool.link}+{_fmt(off)}"
    last = model.njoints - 1
    bodies = [i for i, f in enumerate(model.frames) if f.parentJoint == last]
    fid = bodies[-1]
    return fid, np.zeros(3), model.frames[fid].name


def _report_frame(arm: Arm, spec: Any | None) -> tuple[str, np.ndarray]:
    """Frame the tool point is reported in, and the arm root's pose in it.

    With a spec that mounts the arm on a mobile base, that is the base's root link
    (base_footprint), composed from the fixed joint origins (moving joints at 0),
    so the numbers match `check` and `view`; otherwise the arm's own root link.
    """
    import pinocchio as pin

    model = arm.model
    root = next(f.name for f in model.frames if f.parentJoint == 0 and f.name != "universe")
    T = pin.SE3.Identity()
    if spec is None or spec.mobile_base is None or spec.mount is None:
        return root, T.homogeneous
    by_child = {j.child: j for j in spec.all_joints().values()}
    link = spec.arm_root()
    while link in by_child:
        joint = by_child[link]
        rot = pin.rpy.rpyToMatrix(*joint.origin.rpy)
        T = pin.SE3(rot, np.array(joint.origin.xyz, dtype=float)) * T
        link = joint.parent
    return link, T.homogeneous


def _fmt(v: np.ndarray) -> str:
    return "(" + ",".join(f"{x:g}" for x in v) + ")"


def start_state(arm: Arm, spec: Any | None) -> np.ndarray:
    """The spec's `home` pose if it has one, else zero clamped into the joint limits."""
    q = np.zeros(len(arm.joint_names))
    if spec is not None and "home" in spec.poses:
        home = spec.pose("home")
        q = np.array([home.get(j, 0.0) for j in arm.joint_names], dtype=float)
    return np.clip(q, arm.lower, arm.upper)


def prepare(
    *,
    spec: Any | None,
    urdf: Path | None = None,
    joints: Sequence[str] | None = None,
    trajectory: Path | None = None,
    message: str | None = None,
    kp: Sequence[float] | None = None,
    kd: Sequence[float] | None = None,
    gravity_comp: bool | None = None,
    dt: float | None = None,
    integrator: str = "euler",
    duration: float | None = None,
    clamp: bool = False,
    rate: float | None = None,
    backend: str = "auto",
    trust_xacro: bool = False,
    gate: Callable[[Urdf], None] | None = None,
) -> SimJob:
    """Validate every input and assemble the run; raises InputError on bad input."""
    if (trajectory is None) == (message is None):
        raise InputError(
            "give exactly one of --trajectory FILE or --message '...'", field="--trajectory"
        )
    if integrator not in ("euler", "rk4"):
        raise InputError(
            f"unknown integrator {integrator!r}; valid: euler, rk4", field="--integrator"
        )
    dt = dt if dt is not None else (spec.control.dt if spec is not None else 0.001)
    if not (np.isfinite(dt) and 0 < dt <= 0.1):
        raise InputError(f"must be in (0, 0.1] s, got {dt:g}", field="--dt")
    arm = load_arm(spec, urdf, joints, trust_xacro=trust_xacro, gate=gate)
    limits = {
        n: (float(lo), float(hi))
        for n, lo, hi in zip(arm.joint_names, arm.lower, arm.upper, strict=True)
    }
    if trajectory is not None:
        traj = load_trajectory(trajectory, limits, clamp=clamp)
    else:
        traj = loads_trajectory(str(message), limits, clamp=clamp)
    q0 = start_state(arm, spec)
    ref = build_reference(traj, arm.joint_names, q0)
    gc = (
        gravity_comp
        if gravity_comp is not None
        else bool(spec and spec.control.gravity_compensation)
    )
    cfg = SimConfig(
        _gains(arm, spec, kp, "kp"), _gains(arm, spec, kd, "kd"), dt, integrator, gc, backend
    )
    configs = np.vstack([q0[None, :], ref.sample(traj.times)[0]])
    check_stability(arm, cfg, configs)
    total = duration if duration is not None else traj.duration + SETTLE_EXTRA_S
    if not (np.isfinite(total) and 0 < total <= 3600):
        raise InputError(f"must be in (0, 3600] s, got {total:g}", field="--duration")
    if total / dt > MAX_STEPS:
        raise InputError(
            f"{total:g} s at dt = {dt:g} s is {total / dt:.3g} steps, more than {MAX_STEPS:,}; "
            "shorten --duration or raise --dt",
            field="--duration",
        )
    jsp = spec.arm.joint_state_publisher if spec is not None else None
    rate = rate if rate is not None else (jsp.update_rate if jsp is not None else 10.0)
    if not (np.isfinite(rate) and 0 < rate <= (1.0 + RATE_SLACK) / dt):
        raise InputError(
            f"must be in (0, 1/dt = {1.0 / dt:g}] Hz (one state per time step at most), "
            f"got {rate:g}",
            field="--rate",
        )
    fid, off, label = _tool(arm, spec)
    frame, T_frame_root = _report_frame(arm, spec)
    label = f"{label} in {frame}"
    return SimJob(arm, traj, ref, q0, total, cfg, fid, off, label, float(rate), T_frame_root)


def tool_position(job: SimJob, q: np.ndarray) -> np.ndarray:
    """End-effector point in the reporting frame (see `_report_frame`) at configuration q [m]."""
    import pinocchio as pin

    data = job.arm.model.createData()
    pin.framesForwardKinematics(job.arm.model, data, q)
    p_root = np.asarray(data.oMf[job.tool_frame].act(job.tool_offset), dtype=float)
    return job.T_frame_root[:3, :3] @ p_root + job.T_frame_root[:3, 3]


def run(job: SimJob, progress: Callable[[int, int], None] | None = None) -> SimResult:
    return simulate(job.arm, job.reference, job.q0, job.duration, job.config, progress)
