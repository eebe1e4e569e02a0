"""After a failed plan: is the goal cut off? Scenes whose answer is known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.plan.diagnose import connectivity, reached_in_collision
from armcli.plan.inputs import Loaded, load_context
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC
from tests.plan.conftest import PLAN_FIXTURES

STEP = 0.02  # [rad] the planner's default collision-check step (PlanOptions.step)


@pytest.fixture(scope="module")
def course_post() -> Loaded:
    """A post the forearm meets at arm_base_forearm_joint ~0.4 rad whatever the hand does:
    a band across the 2-D joint space between home (0, 0) and reach (pi/4, pi/4)."""
    return load_context(read_robot(DEFAULT_SPEC), scene=PLAN_FIXTURES / "post_cuts_off.yaml")


def _ends(loaded: Loaded) -> tuple[np.ndarray, np.ndarray]:
    robot = loaded.context.robot
    return robot.pose("home"), robot.pose("reach")


def test_a_post_across_the_joint_space_cuts_the_goal_off(course_post: Loaded) -> None:
    ctx = course_post.context
    start, goal = _ends(course_post)
    lo, hi = ctx.robot.lower, ctx.robot.upper
    # the band by construction: every hand angle collides at shoulder 0.4 rad
    band = [np.array([0.4, h]) for h in np.linspace(lo[1], hi[1], 25)]
    assert not any(ctx.checker.free(x) for x in band)
    found = connectivity(ctx.checker, lo, hi, start, goal, step=STEP)
    assert found.connected is False
    assert "cut off" in found.explain(1.0) and "64 x 64" in found.method


def test_a_box_beside_the_way_leaves_start_and_goal_joined(course_box: Loaded) -> None:
    ctx = course_box.context
    start, goal = _ends(course_box)
    assert not ctx.checker.motion_free(start, goal, STEP)  # the straight sweep is blocked
    found = connectivity(ctx.checker, ctx.robot.lower, ctx.robot.upper, start, goal, step=STEP)
    assert found.connected is True and "--timeout" in found.explain(1.0)


def test_seven_joints_use_a_roadmap(panda: Loaded) -> None:
    ctx = panda.context
    robot = ctx.robot
    start = np.clip(np.zeros(len(robot.joints)), robot.lower, robot.upper)
    goal = np.clip(start + 0.3, robot.lower, robot.upper)  # a free, open space around both
    assert ctx.checker.free(start) and ctx.checker.free(goal)
    found = connectivity(ctx.checker, robot.lower, robot.upper, start, goal, step=STEP)
    assert found.connected is True and "roadmap" in found.method


def test_a_point_inside_an_object_names_the_collision(course: Loaded) -> None:
    shelf = load_context(read_robot(DEFAULT_SPEC), scene=PLAN_FIXTURES / "shelf_at_reach.yaml")
    start = shelf.context.robot.pose("home")
    pair = reached_in_collision(shelf.context, (0.662, 0.0, 0.532), None, start, seed=0)
    assert pair is not None and set(pair) == {"hand_link", "shelf"}
    # out of reach altogether: nothing to blame on the shelf
    assert reached_in_collision(shelf.context, (3.0, 0.0, 0.5), None, start, seed=0) is None
