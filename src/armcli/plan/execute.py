"""Execute a plan: run it through `simulate`'s library and judge the executed motion.

The certified document is simulated as `armcli simulate --trajectory` would run it (same
job preparation: the spec's standalone arm or the given URDF, the spec's gains, its PD
loop), every step kept. The executed motion is broken when a motor torque reaches its
effort limit, a joint moves faster than its velocity limit, or (a robot on a mobile base)
the zero-moment point leaves the support polygon.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from armcli.errors import InputError
from armcli.sim import job as simjob
from armcli.sim import report as simreport
from armcli.sim import tipping
from armcli.sim.armrun import run_balanced
from armcli.sim.options import SimOptions
from armcli.sim.states import Replay
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile

if TYPE_CHECKING:
    from armcli.sim.simulate import SimResult
    from armcli.spec.model import RobotSpec

VELOCITY_TOL = 1e-9  # relative slack on the velocity limit


@dataclass(frozen=True)
class Execution:
    """What executing the plan in simulation showed."""

    metrics: tuple[simreport.JointMetrics, ...]
    peak_effort: np.ndarray  # [N·m or N] per simulated joint
    effort_limit: np.ndarray
    peak_velocity: np.ndarray  # [rad/s or m/s]
    velocity_limit: np.ndarray
    joints: tuple[str, ...]
    tip_margin: float | None  # [m] least zero-moment-point margin; None: fixed base
    problems: tuple[str, ...]  # why the executed motion is broken (empty: it is not)
    states: Replay | None = None  # the executed positions and references (view replays them)

    @property
    def broken(self) -> bool:
        """Whether a limit was broken or the robot tipped."""
        return bool(self.problems)


def check_executable(spec: RobotSpec | None) -> None:
    """InputError before any planning when the plan could not be simulated: no PD gains.

    The run drives each joint with the spec's `control.gains`; a URDF carries none, and
    a failure after planning would leave the plan written and the command failed.
    """
    if spec is None or not spec.control.gains:
        raise InputError(
            "simulates with a spec's control.gains, and this robot has none: "
            "`armcli import` writes a spec with start gains from a URDF, or run "
            "the written plan with `armcli simulate --urdf FILE --kp ... --kd ... "
            "-t PLAN`",
            field="execute",
        )


def execute(file: RobotFile, opts: SimOptions, search: MeshSearch | None = None) -> Execution:
    """Simulate `opts.message` (the plan's document) and judge it; see the module docstring.

    `file`: the robot file the plan was made for (its Robots are built once for both).
    """
    job = simjob.prepare(file, opts)
    notes: list[str] = []
    tip = tipping.prepare(file, job, tipping.TipOptions(), search or MeshSearch(), notes)
    run = run_balanced(job, tip, every_step=True)
    res = run.result
    metrics = tuple(simreport.joint_metrics(res, job.trajectory.duration))
    arm = job.robot
    peak_tau = np.max(np.abs(res.tau), axis=0)
    peak_v = np.max(np.abs(res.v), axis=0)
    vlim = np.where(arm.velocity > 0, arm.velocity, np.inf)
    problems = []
    for i, name in enumerate(arm.names):
        if res.stats.saturated_steps[i] > 0:
            problems.append(f"{name} reaches its effort limit {arm.effort[i]:g}")
        if peak_v[i] > vlim[i] * (1 + VELOCITY_TOL):
            problems.append(f"{name} moves at {peak_v[i]:.4g}, beyond its limit {vlim[i]:g}")
    margin = None
    if run.balance is not None:
        margin = run.balance.min_margin
        if run.balance.tips:
            problems.append(run.balance.error().args[0])
    return Execution(
        metrics,
        peak_tau,
        arm.effort,
        peak_v,
        vlim,
        arm.names,
        margin,
        tuple(problems),
        _states(res),
    )


def _states(res: SimResult) -> Replay:
    """The kept states as a Replay (time, positions, references) for the viewer."""
    names = res.joint_names
    return Replay(
        "<execute>",
        res.t.copy(),
        {j: res.q[:, i].copy() for i, j in enumerate(names)},
        {j: res.q_ref[:, i].copy() for i, j in enumerate(names)},
    )
