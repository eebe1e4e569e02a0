"""IK against FK: closed form for the course arm, Pinocchio's FK for the Panda."""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.errors import PlanningError
from armcli.plan.api import solve_goal
from armcli.plan.ik import POSITION_TOL, ROTATION_TOL, solve_ik, tool_pose
from armcli.plan.inputs import Loaded

# specs/my_robot.yaml: the shoulder sits at base_joint z 0.1 + mount (0.15, 0, 0.2) + arm
# joint z 0.02 in base_footprint; forearm and hand are 0.3 m, the tool 0.3 m along the hand;
# both joints turn about y, so the arm moves in the x-z plane.
SHOULDER = np.array([0.15, 0.0, 0.32])
LINK = 0.3
CASES = 25


def course_tool(q1: float, q2: float) -> np.ndarray:
    """The course arm's tool point in closed form [m]."""
    u1 = np.array([math.sin(q1), 0.0, math.cos(q1)])
    u2 = np.array([math.sin(q1 + q2), 0.0, math.cos(q1 + q2)])
    return SHOULDER + LINK * u1 + LINK * u2


def test_course_ik_matches_closed_form_fk(course: Loaded) -> None:
    ctx = course.context
    rng = np.random.default_rng(7)
    for _ in range(CASES):
        q = rng.uniform(0.1, 1.4, 2)  # inside the limits [0, pi/2], away from the base
        target = course_tool(*q)
        x = solve_goal(ctx, list(target), start=ctx.robot.pose("home"), seed=1)
        assert np.linalg.norm(course_tool(*x) - target) < POSITION_TOL
        assert np.all(x >= ctx.robot.lower) and np.all(x <= ctx.robot.upper)


def test_unreachable_reports_the_closest_distance(course: Loaded) -> None:
    # farthest reach from the shoulder is 2 * LINK = 0.6 m; a point 1.0 m out along x at
    # shoulder height is 0.4 m beyond it
    target = SHOULDER + np.array([1.0, 0.0, 0.0])
    with pytest.raises(PlanningError) as info:
        solve_goal(ctx := course.context, target, start=ctx.robot.pose("home"))
    assert info.value.kind == "ik"
    closest = float(info.value.reason.split("closest: ")[1].split(" m")[0])
    assert closest == pytest.approx(1.0 - 2 * LINK, abs=1e-3)


def test_panda_pose_ik_matches_fk(panda: Loaded) -> None:
    robot = panda.context.robot
    rng = np.random.default_rng(3)
    for _ in range(10):
        q = rng.uniform(robot.lower, robot.upper)
        p, R = tool_pose(robot, q)
        res = solve_ik(robot, p, R, seed=5)
        assert res.x is not None
        p2, R2 = tool_pose(robot, res.x)
        assert np.linalg.norm(p2 - p) < POSITION_TOL
        angle = math.acos(max(-1.0, min(1.0, (np.trace(R2.T @ R) - 1) / 2)))
        assert angle < ROTATION_TOL
