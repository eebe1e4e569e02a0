"""The report's summary of one checked URDF, made after the rules ran (check/run.py).

It holds mass, DoF, the joint table (with the gravity load the dynamics rules found),
the end-effector forward kinematics at each pose, the PD verdict and the notes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from armcli.analysis.rate import RateVerdict
from armcli.analysis.verdict import StabilityReport
from armcli.check.context import Context, poses
from armcli.check.findings import JointRow
from armcli.check.options import CheckOptions
from armcli.check.structure import finite
from armcli.robot.frames import link_frame
from armcli.robot.model import Robot
from armcli.robot.tool import tool_point
from armcli.spec.joint_types import total_dof
from armcli.urdf.doc import Urdf

if TYPE_CHECKING:  # the balance and reach results: imported by their own families
    from armcli.analysis.balance import StaticBalance
    from armcli.analysis.workspace import ReachPoint, Workspace
    from armcli.sim.tipping import ZmpReport


@dataclass(frozen=True)
class PoseRow:
    """One pose in the summary: its joint values [rad or m] and the end-effector position."""

    name: str
    q: tuple[tuple[str, float], ...]
    xyz: tuple[float, float, float]  # end effector in the root link frame [m]


@dataclass(frozen=True)
class Summary:
    """The report's summary of one URDF: mass, DoF, joint table, poses, PD stability, notes."""

    robot: str
    root: str | None
    total_mass: float  # [kg]
    dof: int
    joints: tuple[JointRow, ...]
    end_effector: str
    poses: tuple[PoseRow, ...]
    stability: StabilityReport | None
    notes: tuple[str, ...]
    balance: StaticBalance | None = None  # static balance over the support polygon
    zmp: ZmpReport | None = None  # the --trajectory's zero-moment point
    reach: Workspace | None = None  # the tool point's reach envelope
    reach_points: tuple[ReachPoint, ...] = ()  # the --reach-point verdicts
    rate: RateVerdict | None = None  # the ros2_control controller at its update rate


def summarise(ctx: Context) -> Summary:
    """The summary once the rules ran: joint table, and forward kinematics with the model."""
    urdf = ctx.urdf
    base: dict[str, Any] = {
        "robot": urdf.name,
        "root": ctx.tree.root,
        "total_mass": _total_mass(urdf),
        "dof": total_dof(j.type for j in urdf.joints),
        "joints": ctx.rows,
        "stability": ctx.stability,
        "notes": tuple(ctx.notes),
        "balance": ctx.balance,
        "zmp": ctx.zmp,
        "reach": ctx.reach,
        "reach_points": ctx.reach_points,
        "rate": ctx.rate,
    }
    if ctx.robot is None or _no_arm(ctx):
        return Summary(**base, end_effector="", poses=())
    robot = ctx.robot
    ee_label, ee_frame, ee_offset = _end_effector(urdf, ctx.opts, robot)
    pose_rows = []
    for name, values in poses(ctx):
        xyz = robot.point_position(ee_frame, ee_offset, robot.q(values))
        pose_rows.append(PoseRow(name, tuple(values.items()), tuple(float(x) for x in xyz)))  # type: ignore[arg-type]
    return Summary(**base, end_effector=ee_label, poses=tuple(pose_rows))


def _no_arm(ctx: Context) -> bool:
    """A base without an arm: the tool point (the deepest link) is a wheel on the ground."""
    tool = tool_point(ctx.urdf, ctx.opts.spec)
    return tool is not None and ctx.stance is not None and tool.link in ctx.stance.ground.links


def _total_mass(urdf: Urdf) -> float:
    masses = (lk.inertial.mass for lk in urdf.links if lk.inertial is not None)
    return math.fsum(m for m in masses if m is not None and finite(m) and m > 0)


def _end_effector(
    urdf: Urdf, opts: CheckOptions, robot: Robot
) -> tuple[str, int, tuple[float, float, float]]:
    """The tool point (armcli.robot.tool) as (label, Pinocchio frame id, offset [m])."""
    tool = tool_point(urdf, opts.spec)
    frame = link_frame(robot.model, tool.link) if tool is not None else None
    if tool is None or frame is None:
        return str(robot.model.frames[0].name), 0, (0.0, 0.0, 0.0)
    return tool.label, frame, tool.xyz
