"""What a user names (files, pose names, `q1,q2` values) -> a planning context, joint values.

`load_context` is what `armcli plan` and the viewer's planning panel call: the robot,
its SRDF (or ros-package's collision matrix), the scene, collision model built once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from armcli.errors import InputError
from armcli.io.scene import Scene, load_scene
from armcli.plan.api import PlanningContext, planning_context, values
from armcli.plan.robot import default_joints, load_plan_robot
from armcli.plan.srdf import Srdf, allowed_pairs, read_srdf
from armcli.robot.jointvalues import parse_joint_values, snap_to_limits
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile, lookup_for


@dataclass(frozen=True)
class Loaded:
    """A planning context and where it came from."""

    context: PlanningContext
    robot_file: RobotFile
    scene: Scene


def load_context(
    robot_file: RobotFile,
    *,
    srdf: Path | None = None,
    scene: Path | None = None,
    joints: Sequence[str] | None = None,
    search: MeshSearch | None = None,
    group: str | None = None,
) -> Loaded:
    """The planning context of a robot file, an optional SRDF and an optional scene file.

    `joints` or `group` (a planning group of the SRDF) names the planned joints; neither:
    the spec's arm, or every movable joint of a URDF. `search`: the package lookup
    (--package-dir, the environment); a spec's recorded `packages` are added to it, as for
    every command that reads meshes.
    """
    search = lookup_for(robot_file.spec, search)
    parsed = read_srdf(srdf) if srdf is not None else None
    if group is not None:
        joints = _group_joints(robot_file, parsed, group, joints)
    robot = load_plan_robot(
        robot_file,
        joints=joints,
        search=search,
        group_states=parsed.group_states if parsed is not None else None,
    )
    links = [lk.name for lk in robot.urdf.links]
    obstacles = load_scene(scene, links) if scene is not None else Scene()
    ctx = planning_context(robot, obstacles, allowed_pairs(robot_file, parsed, search))
    return Loaded(ctx, robot_file, obstacles)


def _group_joints(
    robot_file: RobotFile, srdf: Srdf | None, group: str, joints: Sequence[str] | None
) -> list[str]:
    """The movable joints of an SRDF planning group (fixed joints and mimic followers left out)."""
    if joints:
        raise InputError("give `joints` or `group`, not both", field="group")
    if srdf is None:
        raise InputError("a planning group is read from an SRDF: give `srdf` too", field="group")
    movable = set(default_joints(robot_file.robot, None))
    chosen = [j for j in srdf.group_joints(group, robot_file.robot) if j in movable]
    if not chosen:
        raise InputError(f"planning group {group!r} has no movable joint", field="group")
    return chosen


def configuration(
    ctx: PlanningContext, text: str, field: str, notes: list[str] | None = None
) -> np.ndarray:
    """A named pose or joint values in the planned joints' order (robot.jointvalues' rule).

    `q1,q2` or `joint=q,...` [rad or m], numbers or expressions of pi (`pi/2`); a joint a
    named form leaves out stays at rest. A value within jointvalues.SNAP beyond a limit is
    that limit; `notes` gets a line saying so.
    """
    text = text.strip()
    robot = ctx.robot
    if text in robot.poses:
        return robot.pose(text)
    try:
        given = parse_joint_values(text, robot.joints, field)
    except InputError as exc:
        valid = ", ".join(sorted(robot.poses)) or "none"
        if "," in text or "=" in text or len(robot.joints) == 1:
            raise InputError(f"{exc.message}; or a named pose: {valid}", field=field) from None
        raise InputError(
            f"unknown pose {text!r}; valid poses: {valid}, or {len(robot.joints)} "
            f"comma-separated values for {', '.join(robot.joints)} (numbers or pi/2-style)",
            field=field,
        ) from None
    full = {j: given.get(j, robot.robot.rest(j)) for j in robot.joints}
    limits = {
        j: (float(lo), float(hi))
        for j, lo, hi in zip(robot.joints, robot.lower, robot.upper, strict=True)
    }
    snapped, moved = snap_to_limits(full, limits)
    if notes is not None:
        notes.extend(f"{field}: {line}" for line in moved)
    return values(ctx, [snapped[j] for j in robot.joints], field)
