"""Assemble a tuning from user inputs: spec, trajectories (or named poses), options.

Everything that decides what is tuned is here, so tests run it without the CLI: the
arm (the spec's standalone arm built in memory, like `simulate`), the cases, the
perturbed models and the model-based start.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from armcli.defaults import PdLoop
from armcli.errors import InputError
from armcli.io.yaml import load_yaml
from armcli.sim.job import ARM_URDF, SETTLE_EXTRA_S, start_state
from armcli.spec.model import RobotSpec
from armcli.trajectory.message import Trajectory, load_trajectory
from armcli.trajectory.reference import Reference, build_reference
from armcli.tune import gains as gain_vector
from armcli.tune.model_gains import (
    LOOPS,
    STABILITY_MARGIN,
    TARGET_RATIO,
    StartGains,
    start_gains,
)
from armcli.tune.problem import Case, TuneProblem, draw_variants, nominal_robot
from armcli.urdf.source import RobotFile, urdf_text

DEFAULT_ZETA = 1.0  # critically damped
MAX_ROBUST = 1000  # perturbed models per candidate


@dataclass(frozen=True)
class TuneSettings:
    """Options that shape the problem (the search has its own, `SearchOptions`)."""

    joints: tuple[str, ...] | None = None
    loop: str = "implicit"
    zeta: float = DEFAULT_ZETA
    wn: float | None = None  # [rad/s]; None: 2 pi controller_update_rate / TARGET_RATIO
    settle: float = SETTLE_EXTRA_S  # [s] simulated after each trajectory's last point
    robust: int = 0
    mass_scale: tuple[float, float] = (0.8, 1.2)
    friction_scale: tuple[float, float] = (0.5, 2.0)
    seed: int = 0


@dataclass(frozen=True, eq=False)
class TuneJob:
    """A validated tuning: the problem, the start, and the spec's current gains (if any)."""

    problem: TuneProblem
    start: StartGains
    spec_gains: np.ndarray | None  # [kp..., kd...] from control.gains, when all are given


def default_trajectories(spec_path: Path, joints: Sequence[str]) -> list[Path]:
    """The spec's example trajectories: `trajectories/*.yaml` next to the spec, sorted.

    A folder shared by several specs holds other arms' examples too: only files whose
    `joint_names` are all joints of this arm count (an explicit --trajectory is always
    validated in full).
    """
    folder = spec_path.parent / "trajectories"
    if not folder.is_dir():
        return []
    out = []
    for path in sorted(folder.glob("*.yaml")):
        data = load_yaml(path, flow_sets=True).data
        names = data.get("joint_names") if isinstance(data, dict) else None
        if isinstance(names, list) and names and set(map(str, names)) <= set(joints):
            out.append(path)
    return out


def _validate(s: TuneSettings) -> PdLoop:
    """The settings' loop, once every setting is known to be valid."""
    loop = next((x for x in LOOPS if x == s.loop), None)
    if loop is None:
        valid = ", ".join(LOOPS)
        raise InputError(f"unknown loop {s.loop!r}; valid: {valid}", field="TuneSettings.loop")
    if not (math.isfinite(s.zeta) and s.zeta > 0):
        raise InputError(f"must be > 0, got {s.zeta:g}", field="TuneSettings.zeta")
    if s.wn is not None and not (math.isfinite(s.wn) and s.wn > 0):
        raise InputError(f"must be > 0 rad/s, got {s.wn:g}", field="TuneSettings.wn")
    if not (math.isfinite(s.settle) and 0 < s.settle <= 60):
        raise InputError(f"must be in (0, 60] s, got {s.settle:g}", field="TuneSettings.settle")
    if not 0 <= s.robust <= MAX_ROBUST:
        raise InputError(
            f"must be in [0, {MAX_ROBUST}], got {s.robust}", field="TuneSettings.robust"
        )
    for field, (a, b) in (("mass_scale", s.mass_scale), ("friction_scale", s.friction_scale)):
        if not (math.isfinite(a) and math.isfinite(b) and 0 < a <= b):
            raise InputError(f"need 0 < a <= b, got {a:g},{b:g}", field=f"TuneSettings.{field}")
    return loop


def _pose_cases(
    spec: RobotSpec, joints: Sequence[str], q0: np.ndarray, settle: float
) -> list[Case]:
    """Each named pose that differs from the start, as a step at t = 0."""
    cases = []
    for name in sorted(spec.poses):
        pose = spec.pose(name)
        target = np.array([pose.get(j, q) for j, q in zip(joints, q0, strict=True)], dtype=float)
        if np.allclose(target, q0):
            continue
        ref = Reference(knots=np.array([0.0]), coeffs=np.zeros((0, 6, len(joints))), final=target)
        cases.append(Case(f"pose {name}", ref, q0, 0.0, settle))
    return cases


def _traj_case(
    traj: Trajectory, label: str, joints: Sequence[str], q0: np.ndarray, settle: float
) -> Case:
    ref = build_reference(traj, joints, q0)
    return Case(label, ref, q0, traj.duration, traj.duration + settle)


def largest_steps(cases: Sequence[Case], n: int) -> np.ndarray:
    """Per joint, the largest jump between consecutive reference knots (from the start)."""
    out = np.zeros(n)
    for c in cases:
        q_knots = np.vstack([c.q0, c.reference.sample(c.reference.knots)[0], c.reference.final])
        out = np.maximum(out, np.max(np.abs(np.diff(q_knots, axis=0)), axis=0))
    return out


def prepare(file: RobotFile, trajectories: Sequence[Path], s: TuneSettings) -> TuneJob:
    """Validate every input and build the job; raises InputError/SpecError on bad input.

    `file`: a spec's robot file (`RobotFile.of_spec`); its standalone arm is tuned.
    """
    loop = _validate(s)
    spec, spec_path = _spec(file), file.path
    xml = urdf_text(file.arm)
    base = TuneProblem(
        xml,
        ARM_URDF,
        tuple(s.joints or ()),
        spec.control.dt,
        "euler",
        bool(spec.control.gravity_compensation),
        loop,
        1.0,
        (),
        (),
    )
    robot = nominal_robot(base)
    joints = robot.names
    limits = {
        n: (float(lo), float(hi))
        for n, lo, hi in zip(joints, robot.lower, robot.upper, strict=True)
    }
    q0 = start_state(robot, spec)
    paths = list(trajectories) or default_trajectories(spec_path, joints)
    cases = [_traj_case(load_trajectory(p, limits), p.stem, joints, q0, s.settle) for p in paths]
    if not cases:
        cases = _pose_cases(spec, joints, q0, s.settle)
    if not cases:
        raise InputError(
            "nothing to track: give a trajectory file (`trajectories`), or add "
            "trajectories/*.yaml next to the spec or named poses other than the start",
            field="trajectories",
        )
    wn = (
        s.wn
        if s.wn is not None
        else 2 * math.pi * spec.control.controller_update_rate / TARGET_RATIO
    )
    start = start_gains(
        robot,
        dt=spec.control.dt,
        loop=s.loop,
        zeta=s.zeta,
        wn_target=wn,
        steps=largest_steps(cases, len(joints)),
        gravity=not base.gravity_comp,
    )
    variants = draw_variants(robot, s.robust, s.mass_scale, s.friction_scale, s.seed)
    problem = TuneProblem(
        xml,
        ARM_URDF,
        joints,
        spec.control.dt,
        "euler",
        base.gravity_comp,
        loop,
        STABILITY_MARGIN,
        tuple(cases),
        variants,
    ).with_key()
    return TuneJob(problem, start, _spec_gains(spec, joints))


def _spec(file: RobotFile) -> RobotSpec:
    if file.spec is None or not file.compiled:
        raise InputError("tunes a spec's gains: give a spec, not a URDF", file=file.path)
    return file.spec


def _spec_gains(spec: RobotSpec, joints: Sequence[str]) -> np.ndarray | None:
    gains = spec.control.gains
    if not all(j in gains and gains[j].ki == 0.0 for j in joints):
        return None  # missing, or PID: the PD simulator cannot reproduce it
    return gain_vector.stack([gains[j].kp for j in joints], [gains[j].kd for j in joints])
