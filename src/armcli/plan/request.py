"""One planning request, stated as a user states it: start and goal by name, values or a point.

`plan_request` is the library call behind `armcli plan`: load the planning context of
a robot file (its SRDF, a scene), turn the named start and goal into joint values
(inverse kinematics for a point), plan, time and certify. Errors name the request's
fields (`start`, `goal`, `to_xyz`, `to_rpy`, `joints`, `group`, `srdf`); the command
maps them to flags.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from armcli.defaults import MAX_PLAN_TIMEOUT_S
from armcli.errors import InputError, PlanningError
from armcli.plan.api import PlanningContext, PlanOptions, PlanResult, plan_motion, solve_goal
from armcli.plan.diagnose import connectivity, reached_in_collision
from armcli.plan.inputs import configuration, load_context
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile

HOME = "home"  # the start when none is given (the course's named pose)


@dataclass(frozen=True)
class PlanRequest:
    """Where to move from and to, among which obstacles, with which joints and planner."""

    start: str | None = None  # a named pose or "q1,q2,..."; None: `home`
    goal: str | None = None  # a named pose or "q1,q2,..." (exactly one of goal, to_xyz)
    to_xyz: tuple[float, ...] | None = None  # the tool point's goal [m], root frame
    to_rpy: tuple[float, ...] | None = None  # with to_xyz: the tool link's orientation [rad]
    srdf: Path | None = None
    scene: Path | None = None
    joints: tuple[str, ...] | None = None  # None: the arm's (or the group's)
    group: str | None = None  # a planning group of `srdf` (MoveIt's), instead of `joints`
    options: PlanOptions = field(default_factory=PlanOptions)

    def __post_init__(self) -> None:
        if (self.goal is None) == (self.to_xyz is None):
            raise InputError(
                "give exactly one goal: `goal` (a named pose or joint values) "
                "or `to_xyz` (a point for the tool)",
                field="goal",
            )
        if self.to_rpy is not None and self.to_xyz is None:
            raise InputError("`to_rpy` needs `to_xyz`", field="to_rpy")
        timeout = self.options.timeout
        if not 0 < timeout <= MAX_PLAN_TIMEOUT_S:  # NaN fails too
            raise InputError(
                f"must be in (0, {MAX_PLAN_TIMEOUT_S:g}] s, got {timeout:g}", field="timeout"
            )

    def warnings(self) -> list[str]:
        """What looks wrong in the request but is not refused: `to_rpy` given in degrees."""
        rpy = self.to_rpy
        if rpy is None or not any(abs(a) > 2 * math.pi for a in rpy):
            return []
        rad = ",".join(f"{math.radians(a):.4g}" for a in rpy)
        given = ",".join(f"{a:g}" for a in rpy)
        return [
            f"roll, pitch, yaw {given} look like degrees (an angle beyond 2 pi): they are "
            f"radians; {given} degrees are {rad} rad"
        ]

    def describe(self) -> str:
        """`from home to reach`, `from home to xyz 0.2,0,0.15`: the request in words."""
        goal = self.goal
        if goal is None:
            goal = "xyz " + ",".join(f"{v:g}" for v in self.to_xyz or ())
        return f"from {self.start or HOME} to {goal}"


def plan_request(
    robot: RobotFile, request: PlanRequest, search: MeshSearch | None = None
) -> PlanResult:
    """Plan, time and certify `request` for `robot`; PlanningError when no motion is found.

    `search`: the package lookup for meshes (--package-dir, the environment).
    """
    loaded = load_context(
        robot,
        srdf=request.srdf,
        scene=request.scene,
        joints=request.joints,
        search=search,
        group=request.group,
    )
    ctx = loaded.context
    if request.start is None and HOME not in ctx.robot.poses:
        named = ", ".join(sorted(ctx.robot.poses)) or "none"
        raise InputError(
            f"this robot has no `{HOME}` pose: give `start` (positions, or a named pose: {named})",
            field="start",
        )
    notes: list[str] = []
    x_start = configuration(ctx, request.start or HOME, "start", notes)
    if request.goal is not None:
        x_goal = configuration(ctx, request.goal, "goal", notes)
    else:
        assert request.to_xyz is not None  # __post_init__: exactly one goal
        x_goal = _ik_goal(ctx, request, x_start)
    try:
        result = plan_motion(ctx, x_start, x_goal, request.options)
    except PlanningError as exc:
        if exc.kind != "no-path":
            raise
        pr, opts = ctx.robot, request.options
        found = connectivity(
            ctx.checker, pr.lower, pr.upper, x_start, x_goal, step=opts.step, seed=opts.seed
        )
        raise PlanningError("no-path", found.explain(opts.timeout)) from None
    return replace(result, notes=(*result.notes, *notes))


def _ik_goal(ctx: PlanningContext, request: PlanRequest, x_start: np.ndarray) -> np.ndarray:
    """The IK goal; a point the tool reaches only in collision names what collides."""
    assert request.to_xyz is not None
    try:
        return solve_goal(
            ctx, request.to_xyz, request.to_rpy, start=x_start, seed=request.options.seed
        )
    except PlanningError as exc:
        if exc.kind != "ik":
            raise
        pair = reached_in_collision(
            ctx, request.to_xyz, request.to_rpy, x_start, request.options.seed
        )
        if pair is None:
            raise
        raise PlanningError(
            "goal-collision",
            f"the tool point reaches {','.join(f'{v:g}' for v in request.to_xyz)} only in "
            f"collision: {pair[0]} and {pair[1]} (every IK solution found collides)",
            pair=pair,
        ) from None
