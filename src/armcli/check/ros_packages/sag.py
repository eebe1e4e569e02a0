"""`ros-start-sag`: the arm sags at a named pose more than MoveIt accepts: Execute fails.

Held by its controller's gains, it settles farther from where it was commanded than
MoveIt's start tolerance (or the controller's goal tolerance).

A JointTrajectoryController on an effort interface holds each joint with its PID gains;
against gravity a P(D) hold settles g / p away (analysis.sag: armcli's own dynamics, the
integral term counted up to its clamp under the distro's parameter names). MoveIt then
refuses the next plan ("start point deviates from current robot state more than
allowed_start_tolerance", 0.01 rad unless moveit_controllers.yaml says otherwise), and the
controller aborts a goal whose final error exceeds its `constraints.<joint>.goal`. The
poses are the SRDF's group states of the MoveIt config planning for the same robot (and
the spec's, with --spec). The message gives the sag and the p gain that would hold it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from armcli.analysis.sag import Hold, Sag, passing_kp, settle
from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.launch_model import Where
from armcli.check.ros_packages.moveit import MoveItConfig
from armcli.check.ros_packages.params import JTC, Controller
from armcli.check.ros_packages.srdf_names import read
from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf

RULE = "ros-start-sag"
MOCK = ("mock_components/GenericSystem", "fake_components/GenericSystem")


@dataclass(frozen=True)
class Pose:
    """A named pose: its joint values and where it is written."""

    name: str
    q: Mapping[str, float]
    where: Where | None


def check(ctx: PackageContext) -> None:
    """Every effort-commanded JTC of a robot that is not mock hardware, at every pose."""
    done: set[tuple[str, str]] = set()
    for path, robots in ctx.owners().items():
        cf = ctx.controllers(path)
        for c in cf.controllers.values() if cf is not None else ():
            if c.type != JTC or "effort" not in _list(c.params.get("command_interfaces")):
                continue
            for urdf in robots:
                if (c.file, c.name) in done or _mock(urdf):
                    continue
                done.add((c.file, c.name))
                _controller(ctx, c, urdf)


def _list(x: object) -> list[str]:
    return [v for v in x if isinstance(v, str)] if isinstance(x, list) else []


def _mock(urdf: Urdf) -> bool:
    return bool(urdf.ros2_control) and all(rc.hardware in MOCK for rc in urdf.ros2_control)


def _controller(ctx: PackageContext, c: Controller, urdf: Urdf) -> None:
    robot = ctx.model(urdf)
    joints = [j for j in _list(c.params.get("joints")) if robot is not None and j in robot.names]
    if robot is None or not joints:
        return
    raw = c.params.get("gains")
    gains: dict[str, object] = raw if isinstance(raw, dict) else {}
    per: list[dict[str, object]] = []
    for j in joints:
        g = gains.get(j)
        per.append(g if isinstance(g, dict) else {})
    kp = tuple(_num(g.get("p")) for g in per)
    hold = Hold(tuple(joints), kp, tuple(ctx.distro.integral_cap(g) for g in per))
    tolerances, why = _tolerances(ctx, c, urdf, joints)
    if not tolerances:
        return
    for pose in poses(ctx, urdf, joints):
        sag = settle(robot, {**{j: 0.0 for j in joints}, **pose.q}, hold)
        over = [
            (j, sag.deviation(j), tolerances[j])
            for j in joints
            if sag.deviation(j) > tolerances[j] or not sag.converged
        ]
        if over:
            _report(ctx, c, robot, hold, sag, pose, max(over, key=lambda o: o[1] / o[2]), why)


def _num(x: object) -> float:
    return float(x) if isinstance(x, int | float) and not isinstance(x, bool) else 0.0


def _tolerances(
    ctx: PackageContext, c: Controller, urdf: Urdf, joints: list[str]
) -> tuple[dict[str, float], dict[str, str]]:
    """Per joint the tightest of MoveIt's start tolerance and the JTC goal tolerance."""
    moveit = _configs(ctx, joints)
    start = moveit[0].tolerance.value if moveit else None
    constraints = c.params.get("constraints")
    out: dict[str, float] = {}
    why: dict[str, str] = {}
    for j in joints:
        options = []
        if start is not None and start > 0:
            options.append((start, f"MoveIt's allowed_start_tolerance {start:g} rad"))
        goal = constraints.get(j) if isinstance(constraints, dict) else None
        g = _num(goal.get("goal")) if isinstance(goal, dict) else 0.0
        if g > 0:
            options.append((g, f"{c.name}'s goal tolerance {g:g} rad"))
        if options:
            out[j], why[j] = min(options)
    return out, why


def _configs(ctx: PackageContext, joints: list[str]) -> list[MoveItConfig]:
    """The MoveIt configs planning for these joints: their URDF has every one of them.

    (Not by the robot's name: a Gazebo top-level xacro may call the robot otherwise.)
    """
    out = []
    for cfg in ctx.moveit:
        u = ctx.moveit_urdf(cfg)
        if u is not None and set(joints) <= {j.name for j in u.joints}:
            out.append(cfg)
    return out


def poses(ctx: PackageContext, urdf: Urdf, joints: list[str]) -> list[Pose]:
    """The named poses for this robot: SRDF group states, then the spec's."""
    out: list[Pose] = []
    for cfg in _configs(ctx, joints):
        found = read(ctx, cfg)
        if found is None or cfg.srdf is None:
            continue
        srdf, _ = found
        lines = {
            e.where.split(" ", 1)[-1]: e.line
            for e in srdf.entries
            if e.where.startswith("group_state")
        }
        for name, q in srdf.group_states.items():
            if set(q) & set(joints):
                out.append(Pose(name, q, Where(str(cfg.srdf), lines.get(name))))
    if ctx.spec is not None:
        for name in ctx.spec.poses:
            out.append(Pose(name, ctx.spec.pose(name), None))
    return out


def _report(
    ctx: PackageContext,
    c: Controller,
    robot: Robot,
    hold: Hold,
    sag: Sag,
    pose: Pose,
    worst: tuple[str, float, float],
    why: dict[str, str],
) -> None:
    joint, dev, tol = worst
    k = hold.joints.index(joint)
    at = f" ({pose.where.file.rsplit('/', 1)[-1]}:{pose.where.line})" if pose.where else ""
    cap = hold.i_max[k]
    integral = "no integral term" if cap == 0 else f"integral up to {cap:g} N·m"
    gains = f"p {hold.kp[k]:g}, {integral}"
    need = passing_kp(robot, {**{j: 0.0 for j in hold.joints}, **pose.q}, hold, tol)
    torque = abs(sag.torque[joint])
    fix: dict[str, float] = {"p": need} if math.isfinite(need) else {}
    clamp = {"i_clamp": "i_clamp", "either": "i_clamp (or i_clamp_max/i_clamp_min)"}.get(
        ctx.distro.integral_clamp, "i_clamp_max/i_clamp_min"
    )
    if not sag.converged:
        head = f"the gains ({gains}) cannot hold it against gravity"
    else:
        head = (
            f"held by {c.name}'s gains ({gains}) it settles {dev:.3g} rad from where it was "
            f"commanded on {joint!r} (gravity {torque:.3g} N·m)"
        )
    remedy = f"p >= {need:g} holds it" if math.isfinite(need) else "no p holds it"
    ctx.add(
        RULE,
        c.file,
        c.line("gains", joint, "p") or c.line("gains") or c.type_line,
        f"at pose {pose.name!r}{at} {head}, more than {why[joint]}: Execute will fail "
        f'("start point deviates from current robot state"); {remedy}, or an integral '
        f"term i > 0 with {clamp} >= {math.ceil(torque * 100) / 100:g}",
        fix,
        pose=pose.name,
        joint=joint,
        sag=round(dev, 6),
        tolerance=tol,
    )
